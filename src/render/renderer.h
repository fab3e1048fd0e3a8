#pragma once
// The tile renderer: oneTBB over image tiles on all cores. Every pixel depends only on its own
// coordinates, so images are bit-identical for any thread count.
#include <cstdint>
#include <functional>
#include <string>

#include "io/image.h"
#include "render/render_scene.h"
#include "render/shading.h"

namespace lat {

// Radiance seen along a ray at a hit, in place of shade() (render/shading.h): how a mode that
// changes surfaces, not geometry, shades them (e.g. the texture mode's baked maps).
using SurfaceShader = std::function<Vec3(const Ray&, const SurfaceHit&, ShadeCounters&)>;

struct RenderOptions {
    int spp = 1;  // stratified samples per pixel; 1 is the pixel centre
    // Trace rays front to back through partial hits (prefiltered lattices, render/layers.h).
    bool layered = false;
    bool progress = false;
    SurfaceShader shader;  // empty: shade()
};

struct RenderStats {
    double render_ms = 0;
    std::uint64_t primary_rays = 0;
    std::uint64_t shadow_rays = 0;
    std::uint64_t lattice_visits = 0;  // see lattice_visits_this_thread
    int threads = 0;
};

struct RenderOutput {
    ImageF radiance;  // mean of unclamped samples, for float formats
    Image8 display;   // mean of clamped samples, as 8-bit
    RenderStats stats;
};

// The most samples (pixels x samples per pixel) one render may take: hours of work already,
// so a larger request is surely a mistake rather than a job to start.
constexpr std::uint64_t kMaxRenderSamples = std::uint64_t{1} << 32;
// Throws InputError naming `file` (the scene) when width x height x spp is over the limit.
void check_render_budget(const Camera& camera, int spp, const std::string& file);

// Throws Interrupted (util/interrupt.h) when a signal arrives: it stops at the next pixel.
RenderOutput render_image(const RenderScene& rs, const RenderOptions& opt);

// The sample grid for n samples: nx * ny = n with nx, ny as close as possible.
void stratify(int n, int& nx, int& ny);

}  // namespace lat
