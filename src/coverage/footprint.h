#pragma once
// Reading a ray's footprint (math/ray.h) where a shape answers it, and placing the sheet the
// shape answers with on the ray: shared by the shapes that filter (prefiltered tables) or span
// (sub-rays) across the footprint.
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

// The share of a footprint-wide answer's coverage at parameter t of a shadow ray to count
// (RayFootprint::seen_until): none at the start, rising linearly to all of it where the ray's
// line leaves the camera footprint of the surface it leaves. The camera's lines reached that
// surface through whatever lies in their footprint, so the coverage a filter finds there, near
// the start, lies mostly beside those lines and their shadow rays, not on them. (With the
// light at the eye every shadow ray retraces its camera line: nothing casts a shadow that can
// be seen.) A line's own answer needs no share: it is exact.
inline double unseen_share(const RayFootprint& f, double t) {
    return f.seen_until > 0 ? std::clamp(t / f.seen_until, 0.0, 1.0) : 1.0;
}

// The width of r's footprint (in r's space) where r passes nearest `p`, and at r's origin for a
// point behind it: a shape takes its centre, one width for the whole shape.
inline double footprint_width_at(const Ray& r, Vec3 p) {
    const double dd = dot(r.d, r.d);
    const double tc = dot(p - r.o, r.d) / dd;
    const RayFootprint& f = footprint_of(r);
    return (f.width0 + f.spread * std::max(0.0, tc)) * std::sqrt(dd);
}

// Where a sheet (its points summed weighted by their coverage, `alpha` in all) meets ray r:
// at its mean point, which lies near the ray, not on it, at the parameter of that point's
// projection on the ray. False when the sheet covers nothing or the point is outside
// (tmin, tmax).
struct SheetOnRay {
    double t = 0;
    Vec3 p;              // the mean point
    float coverage = 0;  // alpha; sums that round to just under 1 are opaque (1)
    Vec3 facing;         // the unit normal facing the ray, for sheets without normals
};
inline bool sheet_on_ray(Vec3 sum_p, double alpha, const Ray& r, double tmin, double tmax,
                         SheetOnRay& out) {
    if (alpha <= 1e-6) return false;
    const double dd = dot(r.d, r.d);
    out.p = sum_p / alpha;
    out.t = dot(out.p - r.o, r.d) / dd;
    if (!(out.t > tmin && out.t < tmax)) return false;
    out.coverage = alpha >= 1 - 1e-6 ? 1.0f : static_cast<float>(alpha);
    out.facing = -r.d / std::sqrt(dd);
    return true;
}

}  // namespace lat
