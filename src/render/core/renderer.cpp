#include "render/core/renderer.h"

#include <array>
#include <atomic>
#include <chrono>

#include "distributed/deal.h"
#include "distributed/job.h"
#include "distributed/timeline.h"
#include "render/core/camera.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/memory.h"
#include "util/progress.h"
#include "util/stats.h"

namespace lat {
namespace {

constexpr int kTile = 16;

}  // namespace

void check_render_budget(const Camera& camera, int spp, const std::string& file) {
    const std::uint64_t samples = static_cast<std::uint64_t>(camera.width) *
                                  static_cast<std::uint64_t>(camera.height) *
                                  static_cast<std::uint64_t>(std::max(1, spp));
    if (samples > kMaxRenderSamples)
        throw InputError(located_message(
            file, "camera",
            std::to_string(camera.width) + " x " + std::to_string(camera.height) + " pixels x " +
                std::to_string(spp) + " samples per pixel is over the limit of " +
                std::to_string(kMaxRenderSamples) + " samples"));
}

namespace {

// What every tile needs: the integrator, the camera, the samples, the image being filled.
struct TileContext {
    const Integrator& integrator;
    PinholeCamera cam;
    PixelSampler sampler;
    TileGrid grid;
    int spp;
    RenderOutput& out;
};

// Ray counts and stats counters, added up over the tiles of a render.
struct TileCounts {
    std::atomic<std::uint64_t> primary{0}, shadow{0};
    std::array<std::atomic<std::uint64_t>, std::size_t(stats::Counter::kCount)> counted{};
};

void render_tile(const TileContext& tc, int tile, TileCounts& counts) {
    const int w = tc.grid.width, h = tc.grid.height, spp = tc.spp;
    const int x0 = (tile % tc.grid.tiles_x()) * kTile, y0 = (tile / tc.grid.tiles_x()) * kTile;
    ShadeState state;
    // A tile runs on one thread from start to end: its counts are this thread's growth.
    const stats::Tally counted0 = stats::this_thread();
    std::uint64_t rays = 0;
    for (int j = y0; j < std::min(h, y0 + kTile); ++j) {
        for (int i = x0; i < std::min(w, x0 + kTile); ++i) {
            // One relaxed load per pixel (a tile can take seconds at high spp); the rest is
            // skipped, and Interrupted thrown by render_image.
            if (interrupted()) return;
            Vec3 sum, sum_clamped;
            for (int k = 0; k < spp; ++k) {
                const auto [ox, oy] = tc.sampler.offset(static_cast<std::uint64_t>(j) * w + i, k);
                ++rays;
                const Vec3 c = tc.integrator.radiance(tc.cam.trace_ray(i, j, ox, oy), state);
                sum += c;
                sum_clamped += Vec3{std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0),
                                    std::clamp(c.z, 0.0, 1.0)};
            }
            const std::size_t px = (static_cast<std::size_t>(j) * w + i) * 3;
            for (std::size_t ch = 0; ch < 3; ++ch) {
                tc.out.radiance.rgb[px + ch] = static_cast<float>(sum[ch] / spp);
                tc.out.display.rgb[px + ch] = to_byte(sum_clamped[ch] / spp);
            }
        }
    }
    counts.primary.fetch_add(rays, std::memory_order_relaxed);
    counts.shadow.fetch_add(state.shadow_rays, std::memory_order_relaxed);
    const stats::Tally& counted1 = stats::this_thread();
    for (std::size_t c = 0; c < counted0.size(); ++c)
        counts.counted[c].fetch_add(counted1[c] - counted0[c], std::memory_order_relaxed);
}

// Rank 0 receives every rank's figures; the totals become the job's.
void add_up_ranks(const dist::DealReport& deal, RenderStats& st) {
    RankStats mine;
    mine.cpu_ms = st.cpu_ms;
    mine.primary_rays = st.primary_rays;
    mine.shadow_rays = st.shadow_rays;
    mine.counted = st.counted;
    st.ranks = gather_rank_stats(deal, mine);
    if (st.ranks.empty()) return;
    st.primary_rays = st.shadow_rays = 0;
    st.counted = {};
    st.threads = 0;
    st.cpu_ms = 0;
    for (const RankStats& r : st.ranks) {
        st.primary_rays += r.primary_rays;
        st.shadow_rays += r.shadow_rays;
        for (std::size_t c = 0; c < st.counted.size(); ++c) st.counted[c] += r.counted[c];
        st.threads += r.threads;
        st.cpu_ms += r.cpu_ms;
    }
}

}  // namespace

RenderOutput render_image(const Camera& camera, const Integrator& integrator,
                          const RenderOptions& opt) {
    const int w = camera.width, h = camera.height;
    RenderOutput out;
    out.radiance = {w, h, std::vector<float>(static_cast<std::size_t>(w) * h * 3)};
    out.display = {w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3)};
    const PixelSampler sampler(opt.sampler, opt.spp);
    const int spp = sampler.spp();
    const TileGrid grid{w, h, kTile};
    const TileContext tc{integrator, PinholeCamera(camera, spp), sampler, grid, spp, out};

    TileCounts counts;
    const bool across = opt.across_ranks && dist::distributed();
    const auto tiles = static_cast<std::uint32_t>(grid.tiles_x() * grid.tiles_y());
    ProgressBar bar("render", tiles, opt.progress && dist::is_root());
    const auto start = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    dist::DealOptions deal_opt;
    deal_opt.across_ranks = across;
    deal_opt.progress = &bar;
    const dist::DealReport deal = dist::deal(
        tiles, [&](std::uint32_t tile) { render_tile(tc, static_cast<int>(tile), counts); },
        deal_opt);
    bar.finish();
    throw_if_interrupted();
    out.stats.primary_rays = counts.primary.load();
    out.stats.shadow_rays = counts.shadow.load();
    for (std::size_t c = 0; c < out.stats.counted.size(); ++c)
        out.stats.counted[c] = counts.counted[c].load();
    out.stats.threads = deal.threads;
    out.stats.sampler = spp == 1 ? "centre" : sampler_description(opt.sampler).name;
    if (across) {
        gather_tiles(grid, deal, out.radiance.rgb, out.display.rgb);
        dist::mark(dist::Step::kGathered);
    }
    out.stats.cpu_ms = (cpu_seconds() - cpu0) * 1e3;
    if (across) add_up_ranks(deal, out.stats);
    out.stats.render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace lat
