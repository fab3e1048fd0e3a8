#pragma once
// Four parallel rays tested against one part at once: a ray's 2 x 2 sub-rays (sub_rays.h)
// share their direction, so what a part's test derives from the direction alone is derived
// once, and the rest runs two rays to an SSE register (SSE4.1: x86-64-v2). Each lane's
// arithmetic is the scalar test's, operation for operation (SSE2 rounds as scalar doubles do,
// and the build contracts nothing into FMA), so a lane's answer is the scalar test's bit for
// bit (ray_quad_test).
#include <immintrin.h>

#include <cstdint>

#include "geometry/shape.h"

namespace lat {

struct RayQuad {
    alignas(16) double ox[4], oy[4], oz[4];  // the origins
    Vec3 d;                                   // the one direction
    alignas(16) double tmin[4], tmax[4];      // each ray's range, (tmin, tmax)

    Ray ray(int k) const { return {{ox[k], oy[k], oz[k]}, d}; }
};

// The closest crossings found so far of the lanes of a RayQuad: a lane's is valid where its
// bit is set in the mask the tests return. Whole crossings: a shape tested one lane at a time
// (a CSG tree) hands on its leaf, which its surface needs.
struct QuadCrossings {
    Crossing c[4];
};

namespace quad {

using V = __m128d;  // two lanes

inline V splat(double x) { return _mm_set1_pd(x); }
inline V load(const double* p) { return _mm_load_pd(p); }
// Lanes of b where m is set, else of a.
inline V pick(V m, V b, V a) { return _mm_blendv_pd(a, b, m); }
inline V all_lanes() { return _mm_castsi128_pd(_mm_set1_epi64x(-1)); }
inline V copysign(V magnitude, V sign) {
    const V s = splat(-0.0);
    return _mm_or_pd(_mm_andnot_pd(s, magnitude), _mm_and_pd(s, sign));
}
// std::max(x, 0.0): x unless x < 0 (a NaN stays, as does -0).
inline V max0(V x) { return _mm_max_pd(_mm_setzero_pd(), x); }
inline unsigned bits(V m) { return static_cast<unsigned>(_mm_movemask_pd(m)); }
inline V mask_of(unsigned two_bits) {
    return _mm_castsi128_pd(_mm_set_epi64x(-std::int64_t((two_bits >> 1) & 1), -std::int64_t(two_bits & 1)));
}

// Lanes h, h + 1 of a vector field of q.
struct V3 {
    V x, y, z;
};
inline V dot(const V3& a, Vec3 b) { return a.x * splat(b.x) + a.y * splat(b.y) + a.z * splat(b.z); }
inline V dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 origins_minus(const RayQuad& q, int h, Vec3 p) {
    return {load(q.ox + h) - splat(p.x), load(q.oy + h) - splat(p.y), load(q.oz + h) - splat(p.z)};
}

// The roots t0 <= t1 of |w + t d|^2 = r^2 for lanes of w (d shared, dd = |d|^2 > 0), and the
// lanes where the line comes within r of the point (the touch tolerance allowed): what the
// scalar sphere's and cylinder's solve() compute, in their stable closest-point form.
inline V line_roots(const V3& w, Vec3 d, double dd, double r, V& t0, V& t1) {
    const double rr = r * r;
    const V b = -dot(w, d) / splat(dd);
    const V3 p{w.x + splat(d.x) * b, w.y + splat(d.y) * b, w.z + splat(d.z) * b};
    const V disc = splat(rr) - dot(p, p);
    const V met = _mm_cmpnlt_pd(disc, splat(-kTouchTolerance * r * r));
    const V hh = _mm_sqrt_pd(max0(disc) / splat(dd));
    const V c = (dot(w, w) - splat(rr)) / splat(dd);
    const V q = b + copysign(hh, b);
    const V other = c / q;
    const V swap = _mm_cmpgt_pd(q, other);
    const V zero = _mm_cmpeq_pd(q, _mm_setzero_pd());  // both roots 0
    t0 = _mm_andnot_pd(zero, pick(swap, other, q));
    t1 = _mm_andnot_pd(zero, pick(swap, q, other));
    return met;
}

// Keeps in `hits` the lanes (of h, h + 1) where `found` is set, at t with this part number, and
// narrows their tmax to t, as the scalar loop over parts does (first_crossing_of_parts).
inline unsigned keep(RayQuad& q, QuadCrossings& hits, int h, V found, V t, V part) {
    const unsigned m = bits(found);
    if (m == 0) return 0;
    alignas(16) double ts[2], ps[2];
    _mm_store_pd(ts, t);
    _mm_store_pd(ps, part);
    for (int k = 0; k < 2; ++k)
        if (m >> k & 1) {
            q.tmax[h + k] = ts[k];
            hits.c[h + k] = Crossing(ts[k], static_cast<std::uint32_t>(ps[k]), 0);
        }
    return m << h;
}

}  // namespace quad
}  // namespace lat
