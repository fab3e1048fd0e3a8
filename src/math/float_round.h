#pragma once
// Doubles rounded to floats in a chosen direction, for float tests that must not lose what the
// double one finds (Embree's bounds and ray ranges, part boxes' four-lane slab tests). The
// neighbours are found from the bits: std::nextafter is a libm call, and these run several
// times a ray (grass spent 1.4 % of its render in nextafterf).
#include <bit>
#include <cstdint>
#include <limits>

namespace lat {

// std::nextafter(f, +infinity) and std::nextafter(f, -infinity), inline.
inline float next_up(float f) {
    if (!(f < std::numeric_limits<float>::infinity())) return f;  // +infinity, NaN
    if (f == 0) return std::numeric_limits<float>::denorm_min();
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0 ? bits + 1 : bits - 1);
}
inline float next_down(float f) {
    if (!(f > -std::numeric_limits<float>::infinity())) return f;  // -infinity, NaN
    if (f == 0) return -std::numeric_limits<float>::denorm_min();
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0 ? bits - 1 : bits + 1);
}

// The largest float at most x, the smallest at least x, the smallest above x (NaN stays NaN).
inline float float_at_most(double x) {
    const auto f = static_cast<float>(x);
    return static_cast<double>(f) <= x ? f : next_down(f);
}
inline float float_at_least(double x) {
    const auto f = static_cast<float>(x);
    return static_cast<double>(f) >= x ? f : next_up(f);
}
inline float float_above(double x) {
    const auto f = static_cast<float>(x);
    return static_cast<double>(f) > x ? f : next_up(f);
}

}  // namespace lat
