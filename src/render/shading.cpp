#include "render/shading.h"

#include <cmath>

namespace lat {

double shadow_epsilon(Vec3 p) { return 1e-7 * (1.0 + max_component(abs(p))); }

Vec3 shade(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeCounters& counters) {
    const auto visible = [&](std::size_t, const Ray& r, double tmin, double tmax, double) {
        return rs.occluded(r, tmin, tmax, hit.object) ? 0.0 : 1.0;
    };
    return shade_with(rs, ray, hit, counters, visible);
}

}  // namespace lat
