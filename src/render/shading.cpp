#include "render/shading.h"

#include <cmath>

#include "lattice/filtered_shape.h"
#include "render/layers.h"

namespace lat {
namespace {

// Phong with shadows; visible(shadow ray, tmin, tmax) is the share of the light that arrives:
// 0 or 1 for shade(), a transmittance for shade_transmitted().
template <class Visible>
Vec3 shade_with(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeCounters& counters,
                Visible&& visible) {
    const Scene& s = rs.scene();
    const Material& m = s.materials[hit.material];
    const Vec3 v = normalize(-ray.d);
    Vec3 n = hit.n;
    if (dot(n, v) < 0) n = -n;  // face the viewer

    Vec3 c = m.ka * m.color * s.ambient;
    for_each_light(rs, hit.p, counters, visible, [&](const PointLight& light, Vec3 l, double seen) {
        const Vec3 lit = phong_term(m, m.color, n, l, v, light.intensity);
        c += seen == 1 ? lit : lit * seen;
    });
    return c;
}

}  // namespace

double shadow_epsilon(Vec3 p) { return 1e-7 * (1.0 + max_component(abs(p))); }

Vec3 shade(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeCounters& counters) {
    return shade_with(rs, ray, hit, counters, [&](const Ray& r, double tmin, double tmax, double) {
        return rs.occluded(r, tmin, tmax, hit.object) ? 0.0 : 1.0;
    });
}

Vec3 shade_transmitted(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, double width,
                       ShadeCounters& counters) {
    return shade_with(rs, ray, hit, counters, [&](const Ray& r, double tmin, double tmax, double dist) {
        // The footprint of the shaded point, narrowing to the point light.
        set_ray_footprint({width, -width / dist});
        return transmittance(rs, r, tmin, tmax, hit.object);
    });
}

}  // namespace lat
