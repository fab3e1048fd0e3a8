#include "render/core/shading.h"

#include <cmath>

namespace lat {

double shadow_epsilon(Vec3 p) { return 1e-7 * (1.0 + max_component(abs(p))); }

Vec3 shade(const TracedScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeState& state) {
    return shade_with(rs, ray, hit, state, hard_shadows(rs, hit.object, state));
}

}  // namespace lat
