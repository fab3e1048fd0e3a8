#include "geometry/capsule_screen.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "math/float_round.h"

namespace lat {

namespace {

double l1(Vec3 v) { return std::abs(v.x) + std::abs(v.y) + std::abs(v.z); }

}  // namespace

CapsuleScreen::CapsuleScreen(std::span<const Capsule> capsules) {
    if (capsules.empty() || capsules.size() > kMaxCapsules) return;
    Bounds3 box;
    double radius = 0;
    for (const Capsule& c : capsules) {
        box = merge(box, Bounds3{min(c.a, c.b), max(c.a, c.b)});
        radius = std::max(radius, std::abs(c.r));
    }
    centre_ = box.center();
    double reach = 0;
    for (const Capsule& c : capsules) reach = std::max({reach, l1(c.a - centre_), l1(c.b - centre_)});
    extent_ = 2 * reach + radius;
    if (!std::isfinite(extent_) || extent_ > 1e30) return;
    // Lanes past the last capsule repeat the first (their bits are dropped).
    groups_.resize((capsules.size() + 3) / 4);
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        alignas(16) float v[7][4];
        for (std::size_t j = 0; j < 4; ++j) {
            const std::size_t k = 4 * g + j;
            const Capsule& c = capsules[k < capsules.size() ? k : 0];
            const Vec3 a = c.a - centre_, u = c.b - c.a;
            const float f[7] = {float(a.x), float(a.y), float(a.z), float(u.x), float(u.y),
                                float(u.z), float_at_least(std::abs(c.r))};
            for (std::size_t i = 0; i < 7; ++i) v[i][j] = f[i];
        }
        groups_[g] = {_mm_load_ps(v[0]), _mm_load_ps(v[1]), _mm_load_ps(v[2]), _mm_load_ps(v[3]),
                      _mm_load_ps(v[4]), _mm_load_ps(v[5]), _mm_load_ps(v[6])};
    }
    count_ = capsules.size();
}

// The line is moved to its point q nearest the centre and a unit direction n (in double: the
// origin may lie far away), then each capsule's squared distance |s pu - pw|^2 from it is
// taken in float, pw and pu being the capsule's start (relative to q) and axis across the line
// and s the nearest point's parameter, clamped to the segment. Every float in it is at most
// M = |q| + extent_ in magnitude (L1), and some ten operations deep, so it errs by under
// 100 * 2^-24 * M in the distance, s's error included (moving along the segment by s's error
// changes the distance by at most |pu| times it, which is as small). The margin, 1e-4 M, is
// over ten times that, and covers the ends rounded to float as well; the other term covers
// the rounding of q and of Capsule::meets_line's own double test, which reads the far origin,
// both under 1e-15 of |o - centre| (plus M). A capsule is left out only when its distance,
// less all that, exceeds its radius: the double test rejects the line too.
std::uint32_t CapsuleScreen::may_meet(Vec3 o, Vec3 d, double narrower) const {
    if (count_ == 0) return ~std::uint32_t{0};
    // Where the float screen cannot be trusted, it names all the capsules it holds (and no bit
    // past them: callers index their capsules by the bits).
    const auto held = static_cast<std::uint32_t>((std::uint64_t{1} << count_) - 1);
    const double dd = dot(d, d);
    if (!(dd > 0) || !std::isfinite(dd)) return held;
    const Vec3 n = d * (1.0 / std::sqrt(dd)), oc = o - centre_;
    const Vec3 q = oc - n * dot(oc, n);
    const double margin = 1e-4 * (l1(q) + extent_) + 1e-12 * l1(oc) + 1e-6 * std::abs(narrower);
    if (!std::isfinite(margin) || margin > 1e30) return held;
    const __m128 qx = _mm_set1_ps(float(q.x)), qy = _mm_set1_ps(float(q.y)),
                 qz = _mm_set1_ps(float(q.z));
    const __m128 nx = _mm_set1_ps(float(n.x)), ny = _mm_set1_ps(float(n.y)),
                 nz = _mm_set1_ps(float(n.z));
    const __m128 shrink = _mm_set1_ps(float(narrower)), grow = _mm_set1_ps(float(margin));
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), tiny = _mm_set1_ps(FLT_MIN);
    const __m128 sign = _mm_set1_ps(-0.0f);
    std::uint64_t bits = 0;
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        const Group& c = groups_[g];
        const __m128 wx = qx - c.ax, wy = qy - c.ay, wz = qz - c.az;
        const __m128 wn = wx * nx + wy * ny + wz * nz, un = c.ux * nx + c.uy * ny + c.uz * nz;
        const __m128 pwx = wx - nx * wn, pwy = wy - ny * wn, pwz = wz - nz * wn;
        const __m128 pux = c.ux - nx * un, puy = c.uy - ny * un, puz = c.uz - nz * un;
        const __m128 uu = pux * pux + puy * puy + puz * puz;
        const __m128 wu = pwx * pux + pwy * puy + pwz * puz;
        const __m128 s = _mm_min_ps(_mm_max_ps(wu / _mm_max_ps(uu, tiny), zero), one);
        const __m128 vx = s * pux - pwx, vy = s * puy - pwy, vz = s * puz - pwz;
        const __m128 vv = vx * vx + vy * vy + vz * vz;
        // |r - narrower|: the double test squares its radius.
        const __m128 r = _mm_andnot_ps(sign, c.r - shrink) + grow;
        bits |= std::uint64_t(_mm_movemask_ps(_mm_cmple_ps(vv, r * r))) << (4 * g);
    }
    return static_cast<std::uint32_t>(bits) & held;
}

}  // namespace lat
