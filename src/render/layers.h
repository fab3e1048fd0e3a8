#pragma once
// Shading through partial coverage: a camera ray's layers, shaded front to back, and a shadow
// ray's transmittance, as the policy in coverage/layers.h has them.
#include "coverage/layers.h"
#include "render/render_scene.h"
#include "render/shading.h"

namespace lat {

// Radiance along a camera ray; `spread`: the width of its footprint per unit of distance (the
// pixel's angle), which picks the lattices' levels of detail (lattice/filtered_shape.h).
Vec3 trace_layers(const RenderScene& rs, const Ray& ray, double spread, ShadeState& state);

// The share of light that gets through from tmin to tmax along r (unit direction, with its
// footprint: a shadow ray's, RayFootprint::coverage_only) leaving a surface of object `self`,
// whose crossings within its surface tolerance are skipped. last: what blocked the last ray of
// its run, if kept (EmbreeAccel::LastBlocker).
double transmittance(const RenderScene& rs, const Ray& r, double tmin, double tmax,
                     std::uint32_t self, EmbreeAccel::LastBlocker* last = nullptr);

}  // namespace lat
