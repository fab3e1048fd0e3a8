#pragma once
// Phong shading with shadows, exactly as the reference format states it (docs/scene-format.md).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "render/render_scene.h"

namespace lat {

struct ShadeCounters {
    std::uint64_t shadow_rays = 0;
};

// One light's Phong term (diffuse + specular, before shadowing) at a surface of colour `color`
// and material m, unit normal n facing the viewer, unit direction l to the light and v to the
// viewer. The one home of the reflection rule: exact and lattice shading, and the texture
// mode's baked surfaces, all use it.
inline Vec3 phong_term(const Material& m, Vec3 color, Vec3 n, Vec3 l, Vec3 v, Vec3 intensity) {
    const double nl = dot(n, l);
    const Vec3 r = 2 * nl * n - l;
    const double rv = std::max(0.0, dot(r, v));
    const double spec = m.ks * std::pow(rv, m.shininess);
    return intensity * (m.kd * std::max(0.0, nl) * color + Vec3{spec, spec, spec});
}

// Radiance (linear, unclamped) seen along `ray` at `hit`.
Vec3 shade(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeCounters& counters);
// The same with shadow rays that pass partly through prefiltered lattices (render/layers.h);
// `width`: the footprint of the shaded point (world units), which picks the lattices' levels.
Vec3 shade_transmitted(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, double width,
                       ShadeCounters& counters);

// Start of shadow rays: far enough from the surface to skip its own crossing, which double
// precision places within ~1e-12 relative of the true one, and small against any feature.
double shadow_epsilon(Vec3 p);

}  // namespace lat
