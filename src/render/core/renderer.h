#pragma once
// The tile renderer: oneTBB over image tiles on all cores, and over the ranks of an MPI job.
// Every pixel depends only on its own coordinates, so images are bit-identical for any thread
// and rank count.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "distributed/timeline.h"
#include "io/image.h"
#include "render/core/render_scene.h"
#include "render/core/sampler.h"
#include "render/core/shading.h"

namespace lat {

// Radiance seen along a ray at a hit, in place of shade() (render/core/shading.h): how a mode that
// changes surfaces, not geometry, shades them (e.g. the texture mode's baked maps).
using SurfaceShader = std::function<Vec3(const Ray&, const SurfaceHit&, ShadeState&)>;

struct RenderOptions {
    int spp = 1;  // samples per pixel; 1 is the pixel centre
    SamplerKind sampler = kDefaultSampler;  // where the samples fall in the pixel
    // Trace rays front to back through partial hits (prefiltered lattices, render/layers.h).
    bool layered = false;
    bool progress = false;
    SurfaceShader shader;  // empty: shade()
    // Collective: the tiles are dealt across the ranks of the MPI job (distributed/deal.h) and the
    // image is gathered on rank 0; the other ranks return their share of the figures only.
    bool across_ranks = false;
};

// One rank's share of a render spread across an MPI job.
struct RankStats {
    int rank = 0;
    char host[64] = {};
    int threads = 0;
    std::uint32_t tiles = 0, chunks = 0;
    double render_ms = 0;  // first tile dealt to last tile done here
    double wait_ms = 0;    // threads' time waiting for tiles, summed
    double cpu_ms = 0;     // the process's CPU time (all threads) over the render and gather
    std::uint64_t primary_rays = 0, shadow_rays = 0, lattice_visits = 0;
    std::uint64_t peak_memory_bytes = 0;
    dist::Timeline timeline{};  // when each step ended here
};

struct RenderStats {
    // Where the samples fell: the sampler's name, or "centre" at one sample per pixel.
    std::string_view sampler;
    double render_ms = 0;
    double cpu_ms = 0;  // CPU time of the render, all threads (across_ranks: all ranks')
    std::uint64_t primary_rays = 0;
    std::uint64_t shadow_rays = 0;
    std::uint64_t lattice_visits = 0;  // stats::Counter::kLatticeVisits
    int threads = 0;  // across_ranks: summed over ranks; the counts too (on rank 0)
    std::vector<RankStats> ranks;  // across_ranks, on rank 0: one per rank
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

}  // namespace lat
