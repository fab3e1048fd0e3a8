#include "render/renderer.h"

#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <span>

#include "dist/deal.h"
#include "dist/job.h"
#include "dist/message.h"
#include "dist/timeline.h"
#include "render/camera.h"
#include "render/layers.h"
#include "render/shading.h"
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

// What every tile needs: the scene, the camera, the samples, the image being filled.
struct TileContext {
    const RenderScene& rs;
    const RenderOptions& opt;
    PinholeCamera cam;
    PixelSampler sampler;
    int w, h, spp, tiles_x;
    RenderOutput& out;
};

// Ray counts, added up over the tiles of a render.
struct TileCounts {
    std::atomic<std::uint64_t> primary{0}, shadow{0}, visits{0};
};

void render_tile(const TileContext& tc, int tile, TileCounts& counts) {
    const Scene& s = tc.rs.scene();
    const int w = tc.w, h = tc.h, spp = tc.spp;
    const int x0 = (tile % tc.tiles_x) * kTile, y0 = (tile / tc.tiles_x) * kTile;
    ShadeState state;
    // A tile runs on one thread from start to end: its visits are this thread's growth.
    const std::uint64_t visits0 = stats::this_thread(stats::Counter::kLatticeVisits);
    std::uint64_t rays = 0;
    for (int j = y0; j < std::min(h, y0 + kTile); ++j) {
        for (int i = x0; i < std::min(w, x0 + kTile); ++i) {
            // One relaxed load per pixel (a tile can take seconds at high spp); the rest is
            // skipped, and Interrupted thrown by render_image.
            if (interrupted()) return;
            Vec3 sum, sum_clamped;
            for (int k = 0; k < spp; ++k) {
                const auto [ox, oy] = tc.sampler.offset(static_cast<std::uint64_t>(j) * w + i, k);
                const TraceRay traced = tc.cam.trace_ray(i, j, ox, oy);
                const Ray ray = traced.line();
                ++rays;
                SurfaceHit hit;
                Vec3 c = s.background;
                if (tc.opt.layered)
                    c = trace_layers(tc.rs, traced, state);
                else if (tc.rs.intersect(ray, 0.0, kInfinity, hit))
                    c = tc.opt.shader ? tc.opt.shader(ray, hit, state)
                                      : shade(tc.rs, ray, hit, state);
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
    counts.visits.fetch_add(stats::this_thread(stats::Counter::kLatticeVisits) - visits0,
                            std::memory_order_relaxed);
}

// Calls row(first, count) for each row of the chunks' tiles, in order: the index of its first
// pixel in the image and its length in pixels.
template <class F>
void for_each_tile_row(const TileContext& tc, std::span<const dist::Chunk> chunks, F&& row) {
    for (const dist::Chunk& c : chunks)
        for (std::uint32_t tile = c.begin; tile != c.end; ++tile) {
            const int x0 = static_cast<int>(tile % static_cast<std::uint32_t>(tc.tiles_x)) * kTile;
            const int y0 = static_cast<int>(tile / static_cast<std::uint32_t>(tc.tiles_x)) * kTile;
            const auto count = static_cast<std::size_t>(std::min(tc.w, x0 + kTile) - x0);
            for (int j = y0; j < std::min(tc.h, y0 + kTile); ++j)
                row(static_cast<std::size_t>(j) * static_cast<std::size_t>(tc.w) + static_cast<std::size_t>(x0), count);
        }
}

// Rank 0 receives every other rank's tiles: the chunk list, then the radiance and the display
// rows of those tiles, in that order (15 bytes a pixel).
void gather_tiles(const TileContext& tc, const dist::DealReport& mine) {
    std::vector<float>& radiance = tc.out.radiance.rgb;
    std::vector<std::uint8_t>& display = tc.out.display.rgb;
    const std::uint64_t nchunks = mine.chunks.size();
    std::vector<std::span<const std::uint8_t>> pieces{
        {reinterpret_cast<const std::uint8_t*>(&nchunks), sizeof nchunks},
        {reinterpret_cast<const std::uint8_t*>(mine.chunks.data()), nchunks * sizeof(dist::Chunk)}};
    for_each_tile_row(tc, mine.chunks, [&](std::size_t first, std::size_t count) {
        pieces.emplace_back(reinterpret_cast<const std::uint8_t*>(radiance.data() + first * 3),
                            count * 3 * sizeof(float));
    });
    for_each_tile_row(tc, mine.chunks, [&](std::size_t first, std::size_t count) {
        pieces.emplace_back(display.data() + first * 3, count * 3);
    });
    const std::vector<ByteBuffer> all = dist::gather_to_root(pieces);
    if (!dist::is_root()) return;
    // What the other ranks sent is checked before it is copied: every tile of the image from
    // exactly one rank, and rows that fill the message exactly.
    const auto tiles_y = static_cast<std::size_t>((tc.h + kTile - 1) / kTile);
    std::vector<bool> dealt(static_cast<std::size_t>(tc.tiles_x) * tiles_y);
    dist::mark_dealt(mine.chunks, dealt, dist::MessageReader({}, "tile list", 0));
    for (std::size_t r = 1; r < all.size(); ++r) {
        dist::MessageReader in({all[r].data(), all[r].size()}, "tiles message", static_cast<int>(r));
        const std::span<const std::uint8_t> list = in.take(in.read<std::uint64_t>(), sizeof(dist::Chunk));
        std::vector<dist::Chunk> chunks(list.size() / sizeof(dist::Chunk));
        if (!list.empty()) std::memcpy(chunks.data(), list.data(), list.size());
        dist::mark_dealt(chunks, dealt, in);
        for_each_tile_row(tc, chunks, [&](std::size_t first, std::size_t count) {
            in.read(radiance.data() + first * 3, count * 3);
        });
        for_each_tile_row(tc, chunks, [&](std::size_t first, std::size_t count) {
            in.read(display.data() + first * 3, count * 3);
        });
        in.expect_end();
    }
    for (std::size_t t = 0; t < dealt.size(); ++t)
        if (!dealt[t]) throw dist::MessageError("tile " + std::to_string(t) + " came from no rank");
}

// Rank 0 receives every rank's figures; the totals become the job's.
void gather_rank_stats(const dist::DealReport& deal, RenderStats& st) {
    RankStats mine;
    mine.rank = dist::rank();
    const dist::HostName host = dist::HostName::here();
    std::memcpy(mine.host, host.text, sizeof mine.host);
    mine.threads = deal.threads;
    mine.tiles = static_cast<std::uint32_t>(deal.items);
    mine.chunks = static_cast<std::uint32_t>(deal.chunks.size());
    mine.render_ms = deal.seconds * 1e3;
    mine.wait_ms = deal.wait_seconds * 1e3;
    mine.cpu_ms = st.cpu_ms;
    mine.primary_rays = st.primary_rays;
    mine.shadow_rays = st.shadow_rays;
    mine.lattice_visits = st.lattice_visits;
    mine.peak_memory_bytes = peak_rss_bytes();
    mine.timeline = dist::timeline();
    st.ranks = dist::gather_values(mine);
    if (st.ranks.empty()) return;
    st.primary_rays = st.shadow_rays = st.lattice_visits = 0;
    st.threads = 0;
    st.cpu_ms = 0;
    for (const RankStats& r : st.ranks) {
        st.primary_rays += r.primary_rays;
        st.shadow_rays += r.shadow_rays;
        st.lattice_visits += r.lattice_visits;
        st.threads += r.threads;
        st.cpu_ms += r.cpu_ms;
    }
}

}  // namespace

RenderOutput render_image(const RenderScene& rs, const RenderOptions& opt) {
    const Scene& s = rs.scene();
    const int w = s.camera.width, h = s.camera.height;
    RenderOutput out;
    out.radiance = {w, h, std::vector<float>(static_cast<std::size_t>(w) * h * 3)};
    out.display = {w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3)};
    const PixelSampler sampler(opt.sampler, opt.spp);
    const int spp = sampler.spp();
    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    const TileContext tc{rs, opt, PinholeCamera(s.camera, spp), sampler, w, h, spp, tiles_x, out};

    TileCounts counts;
    const bool across = opt.across_ranks && dist::distributed();
    ProgressBar bar("render", static_cast<std::uint64_t>(tiles_x) * tiles_y,
                    opt.progress && dist::is_root());
    const auto start = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    dist::DealOptions deal_opt;
    deal_opt.across_ranks = across;
    deal_opt.progress = &bar;
    const dist::DealReport deal = dist::deal(
        static_cast<std::uint32_t>(tiles_x * tiles_y),
        [&](std::uint32_t tile) { render_tile(tc, static_cast<int>(tile), counts); }, deal_opt);
    bar.finish();
    throw_if_interrupted();
    out.stats.primary_rays = counts.primary.load();
    out.stats.shadow_rays = counts.shadow.load();
    out.stats.lattice_visits = counts.visits.load();
    out.stats.threads = deal.threads;
    out.stats.sampler = spp == 1 ? "centre" : sampler_description(opt.sampler).name;
    if (across) {
        gather_tiles(tc, deal);
        dist::mark(dist::Step::kGathered);
    }
    out.stats.cpu_ms = (cpu_seconds() - cpu0) * 1e3;
    if (across) gather_rank_stats(deal, out.stats);
    out.stats.render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace lat
