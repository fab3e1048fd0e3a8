#include "render/layers.h"

#include "lattice/filtered_shape.h"

namespace lat {

double transmittance(const RenderScene& rs, const Ray& r, double tmin, double tmax,
                     std::uint32_t self) {
    thread_local std::vector<SurfaceHit> partial;
    SurfaceHit opaque;
    if (rs.intersect_layers(r, tmin, tmax, self, opaque, partial, kMinTransmittance)) return 0;
    double trans = 1;
    for (const SurfaceHit& h : partial) trans *= 1 - h.alpha;
    return trans <= kMinTransmittance ? 0 : trans;
}

Vec3 trace_layers(const RenderScene& rs, const Ray& ray, double spread, ShadeCounters& counters) {
    thread_local std::vector<SurfaceHit> partial;
    set_ray_footprint({0, spread});
    SurfaceHit opaque;
    const bool found = rs.intersect_layers(ray, 0.0, kInfinity, EmbreeAccel::kNoObject, opaque, partial);
    // Shading moves the footprint (shadow rays): the layers are all found first.
    const std::vector<SurfaceHit> layers = partial;
    Vec3 c;
    double left = 1;
    for (std::size_t i = 0; i < layers.size(); ++i) {
        const SurfaceHit& h = layers[i];
        const double alpha = i + 1 == kMaxLayers ? 1.0 : h.alpha;
        c += shade_transmitted(rs, ray, h, spread * h.t, counters) * (left * alpha);
        left *= 1 - alpha;
        if (left <= kMinTransmittance) return c;
    }
    return c + (found ? shade_transmitted(rs, ray, opaque, spread * opaque.t, counters)
                      : rs.scene().background) * left;
}

}  // namespace lat
