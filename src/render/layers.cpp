#include "render/layers.h"

#include <algorithm>
#include <cmath>

#include "render/instance_shadows.h"

namespace lat {
namespace {

// Radiance at a layer; `width`: its footprint (world units), which picks the lattices' levels
// of detail for its shadow rays, narrowing to the point light; `weight`: its share of the
// pixel, which with a light's unshadowed term bounds what its shadow ray can change.
Vec3 shade_layer(const TracedScene& rs, const InstanceShadows* maps, const Ray& ray,
                 const SurfaceHit& hit, double width, double weight, ShadeState& state) {
    const auto visible = [&](std::size_t light, const Ray& r, double tmin, double tmax,
                             double dist, const Vec3& unshadowed) {
        // Narrowing to the light; sub-rays along the same world directions in every lattice
        // (coverage/sub_rays.h).
        const double leaving = shadow_width(hit.n, ray.d, r.d, width);
        const TraceRay shadow = TraceRay::shadow(
            r, leaving, dist, seen_until(ray.d, r.d, width, hit.t * length(ray.d)));
        if (maps && maps->mapped(light))
            return maps->visible(light, shadow.ray(), tmin, tmax, hit.object, leaving,
                                 state.kept_blocker(light));
        const double worth = weight * std::max({unshadowed.x, unshadowed.y, unshadowed.z});
        return transmittance(rs, shadow.ray(), tmin, tmax, hit.object, state.kept_blocker(light),
                             worth);
    };
    return shade_with(rs, ray, hit, state, visible);
}

}  // namespace

double transmittance(const TracedScene& rs, const Ray& r, double tmin, double tmax,
                     std::uint32_t self, EmbreeAccel::LastBlocker* last, double worth) {
    thread_local std::vector<AccelHit> partial;  // scratch, reused ray after ray
    if (rs.partial_crossings(r, tmin, tmax, self, partial, shadow_stop(worth), last)) return 0;
    return transmitted(partial);
}

Vec3 trace_layers(const TracedScene& rs, const TraceRay& traced, ShadeState& state,
                  const InstanceShadows* maps) {
    thread_local std::vector<SurfaceHit> partial;  // scratch, reused ray after ray
    const Ray ray = traced.line();  // shaded as its line
    const double spread = traced.footprint.spread;
    SurfaceHit opaque;
    const bool found = rs.intersect_layers(traced.ray(), 0.0, kInfinity, EmbreeAccel::kNoObject,
                                           opaque, partial, camera_stop());
    // Shading moves the footprint (shadow rays): the layers are all found first. (Shadow rays
    // leave `partial` as it is: transmittance has its own.)
    return composite_layers(
        std::span<const SurfaceHit>(partial),
        [&](const SurfaceHit& h, double weight) {
            return shade_layer(rs, maps, ray, h, sheet_width(h.alpha, h.sub_rays, spread * h.t),
                               weight, state);
        },
        [&](double weight) {
            return found ? shade_layer(rs, maps, ray, opaque, spread * opaque.t, weight, state)
                         : rs.scene().background;
        });
}

}  // namespace lat
