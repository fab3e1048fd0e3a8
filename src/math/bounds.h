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

// Slab test: the parameter range [t0, t1] of the line o + t d inside the box, clipped to the
// given range, with inv[a] = 1 / d[a] given (rays of one direction share them; read only where
// d[a] != 0). Returns false if the range is empty. Works for unbounded boxes and zero direction
// components.
inline bool clip_line(const Bounds3& b, const Vec3& o, const Vec3& d, const Vec3& inv, double& t0,
                      double& t1) {
    for (std::size_t a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
            continue;
        }
        double tn = (b.lo[a] - o[a]) * inv[a];
        double tf = (b.hi[a] - o[a]) * inv[a];
        if (tn > tf) std::swap(tn, tf);
        if (tn > t0) t0 = tn;  // NaN-safe ordering: comparisons with NaN leave t0/t1 alone
        if (tf < t1) t1 = tf;
        if (t0 > t1) return false;
    }
    return true;
}
// The reciprocals clip_line wants (0 where d is 0, never read there).
inline Vec3 reciprocals(const Vec3& d) {
    const auto inv = [](double x) { return x != 0.0 ? 1.0 / x : 0.0; };
    return {inv(d.x), inv(d.y), inv(d.z)};
}
inline bool clip_ray(const Bounds3& b, const Ray& r, double& t0, double& t1) {
    return clip_line(b, r.o, r.d, reciprocals(r.d), t0, t1);
}

}  // namespace lat
