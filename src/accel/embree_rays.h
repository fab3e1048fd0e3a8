#pragma once
// Rays and bounds as Embree takes them: in float, widened so that its pruning never loses what
// the double-precision callbacks would find, and kept from values it cannot hold. The
// accelerator's own (accel/embree_accel.cpp).
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>

#include "math/bounds.h"
#include "math/float_round.h"
#include "math/ray.h"

namespace lat::embree_detail {

// A float bound that surely contains the double one, so that Embree's float traversal never
// prunes a primitive the double test would hit. Its margin grows with the coordinates: the
// accelerator hands Embree its world less the scene's centre (EmbreeAccel::Impl::frame).
inline RTCBounds to_rtc_bounds(const Bounds3& b) {
    const double pad = 1e-6 * (max_component(abs(b.lo)) + max_component(abs(b.hi))) + 1e-9;
    RTCBounds r;
    r.lower_x = next_down(static_cast<float>(b.lo.x - pad));
    r.lower_y = next_down(static_cast<float>(b.lo.y - pad));
    r.lower_z = next_down(static_cast<float>(b.lo.z - pad));
    r.upper_x = next_up(static_cast<float>(b.hi.x + pad));
    r.upper_y = next_up(static_cast<float>(b.hi.y + pad));
    r.upper_z = next_up(static_cast<float>(b.hi.z + pad));
    r.align0 = r.align1 = 0;
    return r;
}

// Embree asserts (and aborts) on a ray whose float origin or direction exceeds FLT_LARGE
// (1.844e18) or is NaN, or whose range is NaN. Such a ray comes only from degenerate input (an
// extreme transform or polynomial); it must never reach rtcIntersect1 or rtcOccluded1.
inline bool embree_can_trace(const Ray& r, double tmin, double tmax) {
    constexpr double kLarge = 1.8e18;  // just below Embree's FLT_LARGE
    // Comparisons with NaN are false, so NaN fails too; `&` on 0s and 1s keeps it one branch
    // per ray.
    const auto small = [&](double v) { return static_cast<unsigned>(std::abs(v) < kLarge); };
    return (small(r.o.x) & small(r.o.y) & small(r.o.z) & small(r.d.x) & small(r.d.y) &
            small(r.d.z) & small(tmin) & static_cast<unsigned>(!std::isnan(tmax))) != 0;
}

// Embree drops primitives whose float bounds are not finite or exceed FLT_LARGE; objects that
// large (or unbounded) are tested outside Embree instead, so that they are never lost.
inline bool embree_can_hold(const Bounds3& b) {
    constexpr double kLarge = 1.8e18;  // just below Embree's FLT_LARGE
    return b.finite() && max_component(abs(b.lo)) < kLarge && max_component(abs(b.hi)) < kLarge;
}

// Rays with NaN or infinite parts hit nothing: no object can be tested against them.
inline bool ray_is_finite(const Ray& r, double tmin, double tmax) {
    return is_finite(r.o) && is_finite(r.d) && std::isfinite(tmin) && !std::isnan(tmax);
}

// Embree's float ray for r over [tmin, tmax].
inline void set_rtc_ray(RTCRay& ray, const Ray& r, double tmin, double tmax) {
    ray.org_x = static_cast<float>(r.o.x);
    ray.org_y = static_cast<float>(r.o.y);
    ray.org_z = static_cast<float>(r.o.z);
    ray.dir_x = static_cast<float>(r.d.x);
    ray.dir_y = static_cast<float>(r.d.y);
    ray.dir_z = static_cast<float>(r.d.z);
    // Embree prunes in float: widen the range a little so that it never cuts a double hit.
    ray.tnear = std::max(0.0f, static_cast<float>(tmin) * 0.5f);
    ray.tfar = std::isfinite(tmax) ? float_above(tmax) : INFINITY;
    ray.time = 0;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
}

// Embree's closest-hit traversal; the callbacks record what they find in ctx.
template <class Context>
inline void trace_closest(RTCScene scene, Context& ctx, const Ray& r, double tmin, double tmax) {
    alignas(16) RTCRayHit rh;
    set_rtc_ray(rh.ray, r, tmin, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx.rtc, &rh);
}

// Embree's any-hit traversal (children unsorted, cheaper per node); a callback ends it by
// setting the ray's tfar to -infinity.
template <class Context>
inline void trace_any(RTCScene scene, Context& ctx, const Ray& r, double tmin, double tmax) {
    alignas(16) RTCRay ray;
    set_rtc_ray(ray, r, tmin, tmax);
    rtcOccluded1(scene, &ctx.rtc, &ray);
}

}  // namespace lat::embree_detail
