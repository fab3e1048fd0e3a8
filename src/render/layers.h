#pragma once
// Tracing through prefiltered lattices: a lattice answers a ray with a sheet of
// coverage alpha < 1 (SurfaceHit::alpha), so a ray is traced front to back: each surface met
// adds alpha of its shade, weighted by what is still uncovered, and the ray goes on behind it.
// Shadow rays likewise get the transmittance of what they cross instead of a yes/no. What is
// left of a ray is composed by LayerComposite (geometry/sub_rays.h): sheets of sub-rays block
// each sub-ray once, the tables' sheets are independent draws (the product of 1 - alpha).
// Exact shapes have alpha = 1, so a scene without lattices shades as shade() does.
#include "render/core/traced_scene.h"
#include "render/core/shading.h"

namespace lat {

// Partial surfaces without sub-rays (the tables') composited along a camera ray, at most: the
// last one is taken as opaque. A pixel's share left behind eight sheets of coverage 1/2 is
// 1/256, under an 8-bit step; deeper stacks of partial sheets are rare (the edges of
// overlapping hairs). Sheets of sub-rays are not counted: at most 4 of them add something, and
// once all 4 sub-rays are blocked the ray ends. One traversal finds them all
// (EmbreeAccel::intersect_layers).
inline constexpr int kMaxLayers = 8;
// Below this share left uncovered, the rest of a ray is not traced.
inline constexpr double kMinTransmittance = 1.0 / 1024;

// A shadow ray's footprint leaving a surface is at most this many times the camera ray's there
// (and at least its inverse): the pixel's footprint on the surface seen from the light.
inline constexpr double kMaxShadowWidening = 4;

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
