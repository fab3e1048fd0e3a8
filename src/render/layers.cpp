#include "render/layers.h"

#include "lattice/filtered_shape.h"

namespace lat {

double transmittance(const RenderScene& rs, const Ray& r, double tmin, double tmax,
                     std::uint32_t self) {
    // As EmbreeAccel::occluded: the surface's own shape is skipped within its tolerance.
    double self_until = tmin;
    if (self != EmbreeAccel::kNoObject) {
        const double tol = rs.shape(self).surface_tolerance();
        if (tol > 0) self_until += tol / length(rs.scene().objects[self].xf.inverse_vector(r.d));
    }
    double trans = 1, t = tmin;
    for (int layer = 0; layer < kMaxLayers; ++layer) {
        SurfaceHit h;
        if (!rs.intersect(r, t, tmax, h)) return trans;
        t = h.t;
        if (h.object == self && h.t <= self_until) continue;
        trans *= 1 - h.alpha;
        if (trans <= kMinTransmittance) return 0;
    }
    return 0;  // deeper than kMaxLayers: taken as blocked, as the last layer of a camera ray
}

Vec3 trace_layers(const RenderScene& rs, const Ray& ray, double spread, ShadeCounters& counters) {
    Vec3 c;
    double left = 1, tmin = 0;
    for (int layer = 0; layer < kMaxLayers; ++layer) {
        set_ray_footprint({0, spread});
        SurfaceHit hit;
        if (!rs.intersect(ray, tmin, kInfinity, hit)) return c + rs.scene().background * left;
        const double alpha = layer + 1 == kMaxLayers ? 1.0 : hit.alpha;
        c += shade_transmitted(rs, ray, hit, spread * hit.t, counters) * (left * alpha);
        left *= 1 - alpha;
        if (left <= kMinTransmittance) break;
        tmin = hit.t;
    }
    return c;
}

}  // namespace lat
