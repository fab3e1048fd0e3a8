#include "render/shading.h"

#include <cmath>

namespace lat {

double shadow_epsilon(Vec3 p) { return 1e-7 * (1.0 + max_component(abs(p))); }

Vec3 shade(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeCounters& counters) {
    const Scene& s = rs.scene();
    const Material& m = s.materials[hit.material];
    const Vec3 v = normalize(-ray.d);
    Vec3 n = hit.n;
    if (dot(n, v) < 0) n = -n;  // face the viewer

    Vec3 c = m.ka * m.color * s.ambient;
    const double eps = shadow_epsilon(hit.p);
    for (const PointLight& light : s.lights) {
        const Vec3 to_light = light.position - hit.p;
        const double dist = length(to_light);
        if (dist == 0) continue;
        const Vec3 l = to_light / dist;
        if (s.shadows) {
            ++counters.shadow_rays;
            if (rs.occluded({hit.p, l}, eps, dist * (1 - 1e-12), hit.object)) continue;
        }
        c += phong_term(m, m.color, n, l, v, light.intensity);
    }
    return c;
}

}  // namespace lat
