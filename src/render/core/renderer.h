#pragma once
// The tile renderer: oneTBB over image tiles on all cores, and over the ranks of an MPI job.
// Every pixel depends only on its own coordinates, so images are bit-identical for any thread
// and rank count.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/image.h"
#include "render/core/integrator.h"
#include "render/core/rank_stats.h"
#include "render/core/sampler.h"
#include "scene/scene.h"
#include "util/stats.h"

namespace lat {

struct RenderOptions {
    int spp = 1;  // samples per pixel; 1 is the pixel centre
    SamplerKind sampler = kDefaultSampler;  // where the samples fall in the pixel
    bool progress = false;
    // Collective: the tiles are dealt across the ranks of the MPI job (distributed/deal.h) and
    // the image is gathered on rank 0; the other ranks return their share of the figures only.
    bool across_ranks = false;
};

struct RenderStats {
    // Where the samples fell: the sampler's name, or "centre" at one sample per pixel.
    std::string_view sampler;
    double render_ms = 0;
    double cpu_ms = 0;  // CPU time of the render, all threads (across_ranks: all ranks')
    std::uint64_t primary_rays = 0;
    std::uint64_t shadow_rays = 0;
    // What the stats counters (util/stats.h) added over the render's tiles.
    stats::Tally counted{};
    int threads = 0;  // across_ranks: summed over ranks; the counts too (on rank 0)
    std::vector<RankStats> ranks;  // across_ranks, on rank 0: one per rank

    std::uint64_t count(stats::Counter c) const { return counted[std::size_t(c)]; }
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

// The camera's image, each sample's radiance from `integrator`. Throws Interrupted
// (util/interrupt.h) when a signal arrives: it stops at the next pixel.
RenderOutput render_image(const Camera& camera, const Integrator& integrator,
                          const RenderOptions& opt);

}  // namespace lat
