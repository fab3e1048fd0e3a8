#pragma once
// Phong shading with shadows, exactly as the reference format states it (docs/scene-format.md).
#include <cstdint>

#include "render/render_scene.h"

namespace lat {

struct ShadeCounters {
    std::uint64_t shadow_rays = 0;
};

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
