#pragma once
#include <limits>

#include "math/ray.h"
#include "math/vec.h"

namespace lat {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Axis-aligned box; the default is empty, and an unbounded box has infinite corners.
struct Bounds3 {
    Vec3 lo{kInfinity, kInfinity, kInfinity};
    Vec3 hi{-kInfinity, -kInfinity, -kInfinity};

    static Bounds3 infinite() {
        return {{-kInfinity, -kInfinity, -kInfinity}, {kInfinity, kInfinity, kInfinity}};
    }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    bool finite() const { return is_finite(lo) && is_finite(hi); }
    Vec3 center() const { return (lo + hi) * 0.5; }
    Vec3 extent() const { return hi - lo; }
    Vec3 corner(int i) const {
        return {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
    }
};

inline Bounds3 merge(Bounds3 a, Bounds3 b) { return {min(a.lo, b.lo), max(a.hi, b.hi)}; }
inline Bounds3 merge(Bounds3 a, Vec3 p) { return {min(a.lo, p), max(a.hi, p)}; }
inline Bounds3 intersect(Bounds3 a, Bounds3 b) { return {max(a.lo, b.lo), min(a.hi, b.hi)}; }
inline bool contains(Bounds3 b, Vec3 p) {
    return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z &&
           p.z <= b.hi.z;
}
inline Bounds3 expand(Bounds3 b, double delta) {
    return {b.lo - Vec3{delta, delta, delta}, b.hi + Vec3{delta, delta, delta}};
}

// Slab test: the parameter range [t0, t1] of the ray inside the box, clipped to the given range.
// Returns false if the range is empty. Works for unbounded boxes and zero direction components.
inline bool clip_ray(const Bounds3& b, const Ray& r, double& t0, double& t1) {
    for (int a = 0; a < 3; ++a) {
        const double o = r.o[static_cast<std::size_t>(a)];
        const double d = r.d[static_cast<std::size_t>(a)];
        const double lo = b.lo[static_cast<std::size_t>(a)];
        const double hi = b.hi[static_cast<std::size_t>(a)];
        if (d == 0.0) {
            if (o < lo || o > hi) return false;
            continue;
        }
        const double inv = 1.0 / d;
        double tn = (lo - o) * inv;
        double tf = (hi - o) * inv;
        if (tn > tf) std::swap(tn, tf);
        if (tn > t0) t0 = tn;  // NaN-safe ordering: comparisons with NaN leave t0/t1 alone
        if (tf < t1) t1 = tf;
        if (t0 > t1) return false;
    }
    return true;
}

}  // namespace lat
