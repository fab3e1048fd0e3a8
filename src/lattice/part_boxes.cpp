#include "lattice/part_boxes.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

#include "math/float_round.h"

namespace lat {
namespace {

constexpr double kPad = 1e-4;  // of D; float rounding moves a slab plane by under 1e-6 D

// Crossings may lie a little outside a part's exact bounds (they count as touching with
// kTouchTolerance): the double test pads by far more than that.
Bounds3 padded(const Bounds3& b) {
    const double scale = max_component(abs(b.lo)) + max_component(abs(b.hi)) + length(b.extent());
    return expand(b, 1e-6 * scale + 1e-12);
}

}  // namespace

PartBoxes::PartBoxes(const ShapeParts& primitive, const Bounds3& box, bool tree)
    : center_(box.center()) {
    const double d = length(box.extent()) + max_component(abs(box.lo)) + max_component(abs(box.hi));
    for (std::size_t i = 0; i < primitive.part_count(); ++i) {
        const Bounds3 b = padded(primitive.part_bounds(i));
        exact_.push_back(b);
        // Coordinates relative to the box centre, like the float ray's origin.
        const Bounds3 f = expand(b, kPad * d);
        Box4 q{{float_at_most(f.lo.x - center_.x), float_at_most(f.lo.y - center_.y),
                float_at_most(f.lo.z - center_.z), -INFINITY},
               {float_at_least(f.hi.x - center_.x), float_at_least(f.hi.y - center_.y),
                float_at_least(f.hi.z - center_.z), INFINITY}};
        f_.push_back(q);
    }
    quads_.resize((f_.size() + 3) / 4);
    for (std::size_t i = 0; i < f_.size(); ++i)
        for (std::size_t k = 0; k < 3; ++k) {
            quads_[i / 4].lo[k][i % 4] = f_[i].lo[k];
            quads_[i / 4].hi[k][i % 4] = f_[i].hi[k];
            extent_ = std::max({extent_, std::abs(f_[i].lo[k]), std::abs(f_[i].hi[k])});
        }
    if (tree && f_.size() > kTreeFrom) build_tree();
}

bool PartBoxes::first_crossing(const ShapeParts& primitive, std::span<const std::uint32_t> parts,
                               const Ray& r, double tmin, double tmax, Crossing& hit) const {
    if (parts.size() <= kFewParts)
        return first_crossing_of_parts(primitive, parts, r, tmin, tmax, hit);
    const Ray4 slabs(*this, r);
    Ray4::Range range = slabs.range(tmin, tmax);
    bool found = false;
    slabs.any_listed(parts, range, [&](std::uint32_t part) {
        // A part met before a crossing of its four narrowed the range: tested again.
        if (found && !slabs.meets(part, range)) return false;
        if (primitive.intersect_part(part, r, tmin, tmax, hit)) {
            tmax = hit.t;
            range = slabs.range(tmin, tmax);
            found = true;
        }
        return false;
    });
    return found;
}

bool PartBoxes::any_occludes(const ShapeParts& primitive, std::span<const std::uint32_t> parts,
                             const Ray& r, double tmin, double tmax) const {
    if (parts.size() <= kFewParts) return any_part_occludes(primitive, parts, r, tmin, tmax);
    const Ray4 slabs(*this, r);
    return slabs.any_listed(parts, slabs.range(tmin, tmax), [&](std::uint32_t part) {
        return primitive.occluded_part(part, r, tmin, tmax);
    });
}

std::size_t PartBoxes::near_parts(const Ray& r, double grow, double tmin,
                                  std::span<std::uint32_t> out) const {
    assert(out.size() >= f_.size());
    const Ray4 slabs(*this, r);
    const Ray4::Range range = slabs.range(tmin, kInfinity);
    const Ray4::Grow g = Ray4::grow(grow);
    std::size_t n = 0;
    if (!slabs.in_float()) {
        for (std::uint32_t part = 0; part < f_.size(); ++part)
            if (slabs.meets_grown(part, range, g)) out[n++] = part;
        return n;
    }
    if (!nodes_.empty() && slabs.tame(g)) return tree_near_parts(slabs, range, g, out);
    // Four boxes a test: Plate 5 renders 3 % faster than with one a test (260 -> 252 ms), the
    // same parts.
    const unsigned last = (1u << (f_.size() % 4 == 0 ? 4 : f_.size() % 4)) - 1;
    for (std::size_t k = 0; k < quads_.size(); ++k) {
        unsigned m = slabs.meets_grown4(k, range, g);
        if (k + 1 == quads_.size()) m &= last;
        for (; m != 0; m &= m - 1)
            out[n++] = static_cast<std::uint32_t>(4 * k + std::countr_zero(m));
    }
    return n;
}

// Lane j: the test meets_float runs on parts[j]'s box (meets4).
unsigned PartBoxes::Ray4::meets_listed(const std::uint32_t* parts, std::size_t n,
                                       const Range& r) const {
    assert(n >= 1 && n <= 4);
    if (!use_float_) {
        unsigned m = 0;
        for (std::size_t j = 0; j < n; ++j) m |= static_cast<unsigned>(meets(parts[j], r)) << j;
        return m;
    }
    const Box4* f = boxes_.f_.data();
    // Lanes past n repeat the last part; they are masked off.
    const Box4& b0 = f[parts[0]];
    const Box4& b1 = f[parts[std::min<std::size_t>(1, n - 1)]];
    const Box4& b2 = f[parts[std::min<std::size_t>(2, n - 1)]];
    const Box4& b3 = f[parts[n - 1]];
    __m128 lx = _mm_load_ps(b0.lo), ly = _mm_load_ps(b1.lo), lz = _mm_load_ps(b2.lo),
           lw = _mm_load_ps(b3.lo);
    __m128 hx = _mm_load_ps(b0.hi), hy = _mm_load_ps(b1.hi), hz = _mm_load_ps(b2.hi),
           hw = _mm_load_ps(b3.hi);
    _MM_TRANSPOSE4_PS(lx, ly, lz, lw);  // lx: the four boxes' low x, ly: y, lz: z
    _MM_TRANSPOSE4_PS(hx, hy, hz, hw);
    const __m128 lo[3] = {lx, ly, lz}, hi[3] = {hx, hy, hz};
    return meets4(lo, hi, r) & ((1u << n) - 1);
}

// In float, lo - g rounds by at most 2^-24 (D + g) (coordinates relative to the box centre are
// below D): growing by 1e-5 more covers the part in g, the boxes' padding (1e-4 D) the rest.
PartBoxes::Ray4::Grow PartBoxes::Ray4::grow(double g) {
    return {g, float_at_least(g * (1 + 1e-5))};
}

bool PartBoxes::Ray4::meets_grown(std::uint32_t i, const Range& r, const Grow& g) const {
    if (!use_float_) return meets_double(expand(boxes_.exact_[i], g.g), r);
    const Box4& b = boxes_.f_[i];
    const __m128 gf = _mm_set1_ps(g.f);
    Box4 grown;
    _mm_store_ps(grown.lo, _mm_sub_ps(_mm_load_ps(b.lo), gf));
    _mm_store_ps(grown.hi, _mm_add_ps(_mm_load_ps(b.hi), gf));
    return meets_float(grown, r);
}

PartBoxes::Ray4::Ray4(const PartBoxes& boxes, const Ray& r) : boxes_(boxes), ray_(r) {
    const double dd = dot(r.d, r.d);
    shift_ = dd > 0 ? dot(boxes.center_ - r.o, r.d) / dd : 0.0;
    const Vec3 o = r.o + r.d * shift_ - boxes.center_;
    for (std::size_t k = 0; k < 3; ++k) {
        const double inv = 1.0 / r.d[k];
        if (!(std::abs(inv) < 1e30)) use_float_ = false;  // also catches d = 0
        o_[k] = static_cast<float>(o[k]);
        inv_[k] = static_cast<float>(inv);
    }
    o_[3] = 0, inv_[3] = 1;  // the neutral lane: its slab is (-inf, inf)
    for (std::size_t k = 0; k < 3; ++k)
        ob_[k] = _mm_set1_ps(o_[k]), invb_[k] = _mm_set1_ps(inv_[k]);
}

PartBoxes::Ray4::Range PartBoxes::Ray4::range(double tmin, double tmax) const {
    // The range moved by the shift, widened by more than that subtraction's rounding.
    const double m = 4e-16 * (std::abs(shift_) + (std::isinf(tmin) ? 0 : std::abs(tmin)) +
                              (std::isinf(tmax) ? 0 : std::abs(tmax)));
    return {tmin, tmax, float_at_most(tmin - shift_ - m), float_at_least(tmax - shift_ + m)};
}

bool PartBoxes::Ray4::meets_double(const Bounds3& b, const Range& r) const {
    double tmin = r.tmin, tmax = r.tmax;
    for (std::size_t k = 0; k < 3; ++k) {
        const double o = ray_.o[k], d = ray_.d[k];
        if (d == 0) {
            if (o < b.lo[k] || o > b.hi[k]) return false;
            continue;
        }
        const double t0 = (b.lo[k] - o) / d, t1 = (b.hi[k] - o) / d;
        tmin = std::max(tmin, std::min(t0, t1));
        tmax = std::min(tmax, std::max(t0, t1));
    }
    return tmin <= tmax;
}

}  // namespace lat
