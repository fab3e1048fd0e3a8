#pragma once
// Snapping a ray to its grid point pair in float, four lanes at once (x, y, z and a neutral
// lane), with a certified error bound: the answer is either the one the double-precision snap
// (LatticeFrame::snap_double) gives, bit for bit, or kUnsure, and the caller snaps in double.
// One division instruction instead of three and no branches per axis; kUnsure comes back for
// 0.01-0.7 % of the rays from up to 3 box diagonals away, up to 10 % from 100 (points within
// the margin of a rounding boundary, rays that graze an edge of the box, and rays with a
// direction component of 0 or too small or too large for a float reciprocal).
//
// Error bound (u = 2^-24; o, d the double ray in lattice units; lanes k = x, y, z):
//  - A slab parameter t_k = (b - o_k) / d_k (b = 0 or n_k) is computed from float o_k and d_k:
//    the two conversions, 1/d, b - o and the product round five times, each by a relative u
//    while 1/d is a normal float (checked: |1/d| >= 2^-126, which also turns away a d that
//    overflows to infinity), so it lies within 5.01 u T_k of the double one,
//    T_k = (n_k + |o_k|) / |d_k| (the double's own rounding is 2^-29 times smaller).
//    kSlabError = 6 u covers T_k's float rounding as well. E is the largest of the three.
//  - The entry t0 is the largest slab parameter, the exit t1 the least: the float ones lie
//    within E of the double ones (a maximum moves no more than its arguments).
//  - A point x_k = o_k + d_k t then lies within 2.01 u |o_k| + 3.01 u |d_k t| + |d_k| E of the
//    double one, which is under 1.9 |d_k| E: E >= 6 u (n_k + |o_k|) / |d_k| for every axis k,
//    and |t| is at most the entry (exit) axis's T. The margin m_k is 3 |d_k| E. A coordinate
//    whose distance to the nearest integer is under 1/2 - m_k rounds (and clamps) as the
//    double one does. On the axis of the face the point lies on, the double snap takes the
//    face's level instead of rounding, and so does the float one: the coordinate is within m_k
//    of that integer. (When two axes are nearly tied for the face, the point is on their edge,
//    one grid point either way.)
//  - The ray meets the box (t0 <= t1 in double) surely when t0 + E < t1 - E, and misses it
//    surely when t0 - E > t1 + E (tested with 2 E, for the rounding of the sums).
#include <immintrin.h>

#include <array>
#include <cmath>
#include <cstdint>

#include "lattice/boundary_grid.h"
#include "math/vec.h"

namespace lat {

enum class FloatSnap { kMiss, kPair, kUnsure };

namespace float_snap_detail {

// From registers, not memory: a Vec3 just stored field by field and read back as pairs would
// stall store forwarding.
inline __m128 load3(const Vec3& v, float pad) {
    const __m128 xy = _mm_cvtpd_ps(_mm_setr_pd(v.x, v.y));
    const __m128 z = _mm_cvtpd_ps(_mm_set_sd(v.z));
    return _mm_insert_ps(_mm_movelh_ps(xy, z), _mm_set_ss(pad), 0x30);  // lane 3 = pad
}
// The largest (least) of lanes 0-2, in every lane.
inline __m128 hmax3(__m128 v) {
    const __m128 m = _mm_max_ps(v, _mm_max_ps(_mm_shuffle_ps(v, v, _MM_SHUFFLE(0, 2, 0, 1)),
                                              _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 1, 2))));
    return _mm_shuffle_ps(m, m, 0);
}
inline __m128 hmin3(__m128 v) {
    const __m128 m = _mm_min_ps(v, _mm_min_ps(_mm_shuffle_ps(v, v, _MM_SHUFFLE(0, 2, 0, 1)),
                                              _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 1, 2))));
    return _mm_shuffle_ps(m, m, 0);
}
inline __m128 absf(__m128 v) {
    return _mm_andnot_ps(_mm_set1_ps(-0.0f), v);
}

// One end of the chord, at t (splatted) with error e (splatted): its grid point in c, and the
// lanes whose rounding is certain (the float rounding of m and 1/2 - m is far inside its
// slack).
inline __m128 end_point(__m128 o, __m128 d, __m128 n, __m128 t, __m128 e, __m128& c) {
    const __m128 x = _mm_add_ps(o, _mm_mul_ps(d, t));
    const __m128 m = _mm_mul_ps(absf(d), _mm_mul_ps(_mm_set1_ps(3.0f), e));
    const __m128 r = _mm_round_ps(x, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    c = _mm_min_ps(_mm_max_ps(r, _mm_setzero_ps()), n);
    return _mm_cmplt_ps(absf(_mm_sub_ps(x, r)), _mm_sub_ps(_mm_set1_ps(0.5f), m));
}

inline void store(__m128 c, GridPoint& g) {
    alignas(16) std::int32_t i[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(i), _mm_cvtps_epi32(c));
    g.x = i[0], g.y = i[1], g.z = i[2];
}

}  // namespace float_snap_detail

// o, d: the ray in lattice units; cells: the box is [0, cells]. On kPair, entry and exit are
// the grid points LatticeFrame::snap_double gives.
inline FloatSnap snap_float(const Vec3& o, const Vec3& d, const std::array<int, 3>& cells,
                            GridPoint& entry, GridPoint& exit) {
    using namespace float_snap_detail;
    constexpr float kSlabError = 6 * 0x1p-24f;
    const __m128 of = load3(o, 0.0f), df = load3(d, 1.0f);  // lane 3 is neutral
    const __m128 n = _mm_cvtepi32_ps(_mm_set_epi32(0, cells[2], cells[1], cells[0]));
    const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), df);
    const __m128 ta = _mm_mul_ps(_mm_sub_ps(_mm_setzero_ps(), of), inv);
    const __m128 tb = _mm_mul_ps(_mm_sub_ps(n, of), inv);
    const __m128 err =
        _mm_mul_ps(_mm_set1_ps(kSlabError), _mm_mul_ps(_mm_add_ps(n, absf(of)), absf(inv)));
    // A zero or too small direction component makes its error infinite or NaN (which fails
    // the comparison too), a huge one its reciprocal denormal or 0: the double snap handles
    // such rays.
    const __m128 usable = _mm_and_ps(_mm_cmplt_ps(err, _mm_set1_ps(INFINITY)),
                                     _mm_cmpge_ps(absf(inv), _mm_set1_ps(0x1p-126f)));
    if ((_mm_movemask_ps(usable) & 7) != 7) return FloatSnap::kUnsure;
    const __m128 e = hmax3(err);
    const __m128 t0 = hmax3(_mm_min_ps(ta, tb)), t1 = hmin3(_mm_max_ps(ta, tb));
    // Twice E: the float sums round too (by far less than E).
    const float a = _mm_cvtss_f32(t0), b = _mm_cvtss_f32(t1), e2 = 2 * _mm_cvtss_f32(e);
    if (!(a + e2 < b - e2)) return a - e2 > b + e2 ? FloatSnap::kMiss : FloatSnap::kUnsure;
    __m128 c0, c1;
    const __m128 safe =
        _mm_and_ps(end_point(of, df, n, t0, e, c0), end_point(of, df, n, t1, e, c1));
    if ((_mm_movemask_ps(safe) & 7) != 7) return FloatSnap::kUnsure;
    store(c0, entry);
    store(c1, exit);
    return FloatSnap::kPair;
}

}  // namespace lat
