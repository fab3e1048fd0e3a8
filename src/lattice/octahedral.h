#pragma once
// Unit vectors in two small integers by the octahedral map (Meyer et al. 2010; Cigolle et al.
// 2014): the sphere is folded onto the octahedron |x|+|y|+|z| = 1 and flattened to a square.
#include <emmintrin.h>

#include <cmath>
#include <cstdint>

#include "math/vec.h"

namespace lat {

struct Oct {
    std::uint32_t u = 0, v = 0;  // each in [0, 2^bits - 1]
};

inline double sign_not_zero(double v) { return v >= 0 ? 1.0 : -1.0; }

// The point of the square [-1, 1]^2 that n maps to. Both halves are worked out and one is
// picked without a branch: whether n.z >= 0 is a coin toss for a table's hits, known only at
// the end of the normal's divisions, and a mispredicted branch there serialises the hits.
// (Each value is the one the scalar expressions give: SSE2 rounds as scalar doubles do.)
inline Vec2 oct_fold(Vec3 n) {
    const double l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
    const __m128d p = _mm_div_pd(_mm_set_pd(n.y, n.x), _mm_set1_pd(l1));  // px, py
    const __m128d one = _mm_set1_pd(1.0), abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7FFFFFFFFFFFFFFF));
    const __m128d abs_swapped = _mm_and_pd(_mm_shuffle_pd(p, p, 1), abs_mask);  // |py|, |px|
    const __m128d nonneg = _mm_cmpge_pd(p, _mm_setzero_pd());  // sign_not_zero
    const __m128d sign = _mm_or_pd(_mm_and_pd(nonneg, one), _mm_andnot_pd(nonneg, _mm_set1_pd(-1.0)));
    const __m128d folded = _mm_mul_pd(_mm_sub_pd(one, abs_swapped), sign);
    const __m128d upper = _mm_cmpge_pd(_mm_set1_pd(n.z), _mm_setzero_pd());
    const __m128d q = _mm_or_pd(_mm_and_pd(upper, p), _mm_andnot_pd(upper, folded));
    return {_mm_cvtsd_f64(q), _mm_cvtsd_f64(_mm_unpackhi_pd(q, q))};
}

inline Oct oct_encode(Vec3 n, int bits) {
    const auto [px, py] = oct_fold(n);
    const double scale = static_cast<double>((1u << bits) - 1);
    // Non-negative values: adding one half and truncating rounds them (no libm call).
    return {static_cast<std::uint32_t>((px * 0.5 + 0.5) * scale + 0.5),
            static_cast<std::uint32_t>((py * 0.5 + 0.5) * scale + 0.5)};
}

inline Vec3 oct_decode(Oct o, int bits) {
    const double scale = static_cast<double>((1u << bits) - 1);
    const double px = o.u / scale * 2 - 1, py = o.v / scale * 2 - 1;
    Vec3 n{px, py, 1 - std::abs(px) - std::abs(py)};
    if (n.z < 0) {
        const double ox = (1 - std::abs(n.y)) * sign_not_zero(n.x);
        const double oy = (1 - std::abs(n.x)) * sign_not_zero(n.y);
        n.x = ox;
        n.y = oy;
    }
    return normalize(n);
}

// The code among the four nearest grid points that decodes closest to n: the rounding above
// is not optimal on the folded map, and this halves the worst angle error for the same bits.
inline Oct oct_encode_precise(Vec3 n, int bits) {
    const Oct r = oct_encode(n, bits);
    const auto [px, py] = oct_fold(n);
    const double scale = static_cast<double>((1u << bits) - 1);
    const auto u0 = static_cast<std::uint32_t>(std::floor((px * 0.5 + 0.5) * scale));
    const auto v0 = static_cast<std::uint32_t>(std::floor((py * 0.5 + 0.5) * scale));
    Oct best = r;
    double best_dot = dot(oct_decode(r, bits), n);
    const std::uint32_t top = (1u << bits) - 1;
    for (std::uint32_t du = 0; du < 2; ++du)
        for (std::uint32_t dv = 0; dv < 2; ++dv) {
            const Oct c{std::min(u0 + du, top), std::min(v0 + dv, top)};
            const double d = dot(oct_decode(c, bits), n);
            if (d > best_dot) {
                best_dot = d;
                best = c;
            }
        }
    return best;
}

}  // namespace lat
