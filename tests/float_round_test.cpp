// math/float_round.h: the inline neighbours and directed roundings answer as std::nextafter and
// the definitions they stand for, on the values where bit tricks go wrong (zeros of both signs,
// subnormals, the largest finite float, infinities, NaN) and on many ordinary ones.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "math/float_round.h"

namespace lat {
namespace {

using Lim = std::numeric_limits<float>;

// The same float, bit for bit (so -0 is not 0), or both NaN.
bool same(float a, float b) {
    return std::isnan(a) ? std::isnan(b)
                         : std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

std::vector<float> edge_floats() {
    std::vector<float> v = {0.0f,
                            -0.0f,
                            Lim::denorm_min(),
                            -Lim::denorm_min(),
                            Lim::min(),
                            -Lim::min(),
                            Lim::max(),
                            -Lim::max(),
                            Lim::infinity(),
                            -Lim::infinity(),
                            Lim::quiet_NaN(),
                            1.0f,
                            -1.0f,
                            std::nextafter(Lim::min(), 0.0f)};
    std::mt19937 rng(7);
    std::uniform_int_distribution<std::uint32_t> bits;
    for (int i = 0; i < 20000; ++i) v.push_back(std::bit_cast<float>(bits(rng)));
    return v;
}

TEST(FloatRound, NeighboursAreNextafters) {
    for (const float f : edge_floats()) {
        EXPECT_TRUE(same(next_up(f), std::nextafter(f, Lim::infinity()))) << f;
        EXPECT_TRUE(same(next_down(f), std::nextafter(f, -Lim::infinity()))) << f;
    }
}

std::vector<double> edge_doubles() {
    std::vector<double> v;
    for (const float f : edge_floats()) {
        const double d = f;
        v.insert(v.end(), {d, std::nextafter(d, HUGE_VAL), std::nextafter(d, -HUGE_VAL)});
    }
    const double big = double(Lim::max());
    v.insert(v.end(), {1e300, -1e300, big * (1 + 1e-9), -big * (1 + 1e-9), 1e-50, -1e-50, 0.1, -0.1,
                       1.0 / 3});
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1e6, 1e6);
    for (int i = 0; i < 20000; ++i) v.push_back(u(rng));
    return v;
}

TEST(FloatRound, DirectedRoundingsBracketTheDouble) {
    for (const double x : edge_doubles()) {
        const float lo = float_at_most(x), hi = float_at_least(x), above = float_above(x);
        if (std::isnan(x)) {
            EXPECT_TRUE(std::isnan(lo) && std::isnan(hi) && std::isnan(above));
            continue;
        }
        // The largest float at most x, the smallest at least x, the smallest above x.
        EXPECT_LE(double(lo), x) << x;
        EXPECT_GE(double(hi), x) << x;
        if (!std::isinf(lo)) {
            EXPECT_GT(double(next_up(lo)), x) << x;
        }
        if (!std::isinf(hi)) {
            EXPECT_LT(double(next_down(hi)), x) << x;
        }
        if (!(std::isinf(x) && x > 0)) {
            EXPECT_GT(double(above), x) << x;
        }
        if (!std::isinf(above)) {
            EXPECT_LE(double(next_down(above)), x) << x;
        }
    }
}

}  // namespace
}  // namespace lat
