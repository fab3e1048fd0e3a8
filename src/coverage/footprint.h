#pragma once
// Reading a ray's footprint (math/ray.h) where a shape answers it: the one formula for its
// width at the shape, shared by the shapes that filter (prefiltered tables) or span (sub-rays)
// across it.
#include <algorithm>
#include <cmath>

#include "math/ray.h"

namespace lat {

// What a ray without a footprint is taken to have: a zero one (its own line: the finest level,
// no directions across it, no bound).
inline constexpr RayFootprint kNoFootprint{};
inline const RayFootprint& footprint_of(const Ray& r) {
    return r.footprint ? *r.footprint : kNoFootprint;
}

// The width of r's footprint (in r's space) where r passes nearest `p`, and at r's origin for a
// point behind it: a shape takes its centre, one width for the whole shape.
inline double footprint_width_at(const Ray& r, Vec3 p) {
    const double dd = dot(r.d, r.d);
    const double tc = dot(p - r.o, r.d) / dd;
    const RayFootprint& f = footprint_of(r);
    return (f.width0 + f.spread * std::max(0.0, tc)) * std::sqrt(dd);
}

}  // namespace lat
