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

// Start of shadow rays: far enough from the surface to skip its own crossing, which double
// precision places within ~1e-12 relative of the true one, and small against any feature.
double shadow_epsilon(Vec3 p);

// The lights that reach p, each with its shadow ray cast (when the scene has shadows):
// visible(shadow ray, tmin, tmax, distance) gives the share of the light that arrives, and
// lit(light, unit direction to it, share) is called when that is above 0. The one home of the
// light loop: shade() and the texture mode's baked surfaces both go through it.
template <class Visible, class Lit>
void for_each_light(const RenderScene& rs, Vec3 p, ShadeCounters& counters, Visible&& visible,
                    Lit&& lit) {
    const Scene& s = rs.scene();
    const double eps = shadow_epsilon(p);
    for (const PointLight& light : s.lights) {
        const Vec3 to_light = light.position - p;
        const double dist = length(to_light);
        if (dist == 0) continue;
        const Vec3 l = to_light / dist;
        double seen = 1;
        if (s.shadows) {
            ++counters.shadow_rays;
            seen = visible(Ray{p, l}, eps, dist * (1 - 1e-12), dist);
            if (seen <= 0) continue;
        }
        lit(light, l, seen);
    }
}

// Phong with shadows; visible(shadow ray, tmin, tmax, distance) is the share of the light that
// arrives: 0 or 1 for shade(), a transmittance through partial hits for layered rays
// (render/layers.h).
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

}  // namespace lat
