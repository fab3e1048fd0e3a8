#include "lattice/part_boxes.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lat {
namespace {

constexpr double kPad = 1e-4;  // of D; float rounding moves a slab plane by under 1e-6 D

// Crossings may lie a little outside a part's exact bounds (they count as touching with
// kTouchTolerance): the double test pads by far more than that.
Bounds3 padded(const Bounds3& b) {
    const double scale = max_component(abs(b.lo)) + max_component(abs(b.hi)) + length(b.extent());
    return expand(b, 1e-6 * scale + 1e-12);
}

float down(double x) {
    const auto f = static_cast<float>(x);
    return static_cast<double>(f) <= x ? f : std::nextafter(f, -INFINITY);
}
float up(double x) {
    const auto f = static_cast<float>(x);
    return static_cast<double>(f) >= x ? f : std::nextafter(f, INFINITY);
}

}  // namespace

PartBoxes::PartBoxes(const Shape& primitive, const Bounds3& box) : center_(box.center()) {
    const double d = length(box.extent()) + max_component(abs(box.lo)) + max_component(abs(box.hi));
    for (std::size_t i = 0; i < primitive.primitive_count(); ++i) {
        const Bounds3 b = padded(primitive.primitive_bounds(i));
        exact_.push_back(b);
        // Coordinates relative to the box centre, like the float ray's origin.
        const Bounds3 f = expand(b, kPad * d);
        Box4 q{{down(f.lo.x - center_.x), down(f.lo.y - center_.y), down(f.lo.z - center_.z),
                -INFINITY},
               {up(f.hi.x - center_.x), up(f.hi.y - center_.y), up(f.hi.z - center_.z), INFINITY}};
        f_.push_back(q);
    }
}

bool PartBoxes::first_crossing(const Shape& primitive, std::span<const std::uint32_t> parts,
                               const Ray& r, double tmin, double tmax, Crossing& hit) const {
    const Ray4 slabs(*this, r);
    Ray4::Range range = slabs.range(tmin, tmax);
    bool found = false;
    for (const std::uint32_t part : parts) {
        if (!slabs.meets(part, range)) continue;
        if (primitive.intersect_primitive(part, r, tmin, tmax, hit)) {
            tmax = hit.t;
            range = slabs.range(tmin, tmax);
            found = true;
        }
    }
    return found;
}

std::size_t PartBoxes::near_parts(const Ray& r, double grow, double tmin,
                                  std::span<std::uint32_t> out) const {
    assert(out.size() >= f_.size());
    const Ray4 slabs(*this, r);
    const Ray4::Range range = slabs.range(tmin, kInfinity);
    const Ray4::Grow g = Ray4::grow(grow);
    std::size_t n = 0;
    for (std::uint32_t part = 0; part < f_.size(); ++part)
        if (slabs.meets_grown(part, range, g)) out[n++] = part;
    return n;
}

// In float, lo - g rounds by at most 2^-24 (D + g) (coordinates relative to the box centre are
// below D): growing by 1e-5 more covers the part in g, the boxes' padding (1e-4 D) the rest.
PartBoxes::Ray4::Grow PartBoxes::Ray4::grow(double g) {
    return {g, up(g * (1 + 1e-5))};
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
}

PartBoxes::Ray4::Range PartBoxes::Ray4::range(double tmin, double tmax) const {
    // The range moved by the shift, widened by more than that subtraction's rounding.
    const double m = 4e-16 * (std::abs(shift_) + (std::isinf(tmin) ? 0 : std::abs(tmin)) +
                              (std::isinf(tmax) ? 0 : std::abs(tmax)));
    return {tmin, tmax, down(tmin - shift_ - m), up(tmax - shift_ + m)};
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
