#include "render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>

#include "lattice/lattice_shape.h"
#include "render/camera.h"
#include "render/layers.h"
#include "render/shading.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/progress.h"

namespace lat {
namespace {

constexpr int kTile = 16;

// A well-mixed hash (splitmix64 finaliser): jitter that depends on the pixel and sample only.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

double unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

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

void stratify(int n, int& nx, int& ny) {
    nx = static_cast<int>(std::sqrt(static_cast<double>(n)));
    while (nx > 1 && n % nx != 0) --nx;
    ny = n / nx;
}

RenderOutput render_image(const RenderScene& rs, const RenderOptions& opt) {
    const Scene& s = rs.scene();
    const int w = s.camera.width, h = s.camera.height;
    const PinholeCamera cam(s.camera);
    RenderOutput out;
    out.radiance = {w, h, std::vector<float>(static_cast<std::size_t>(w) * h * 3)};
    out.display = {w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3)};
    int sx_n, sy_n;
    stratify(std::max(1, opt.spp), sx_n, sy_n);
    const int spp = sx_n * sy_n;
    // A sample's footprint per unit distance: the pixel's angle, shared by its samples.
    const double spread = 2 * std::tan(s.camera.fov_y_deg * M_PI / 360.0) / h / std::sqrt(double(spp));

    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    std::atomic<std::uint64_t> primary{0}, shadow{0}, visits{0};
    ProgressBar bar("render", static_cast<std::uint64_t>(tiles_x) * tiles_y, opt.progress);
    const auto start = std::chrono::steady_clock::now();

    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y, 1), [&](const tbb::blocked_range<int>& range) {
        for (int tile = range.begin(); tile != range.end(); ++tile) {
            const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
            ShadeCounters counters;
            // A tile runs on one thread from start to end: its visits are this thread's growth.
            const std::uint64_t visits0 = lattice_visits_this_thread();
            std::uint64_t rays = 0;
            for (int j = y0; j < std::min(h, y0 + kTile); ++j) {
                for (int i = x0; i < std::min(w, x0 + kTile); ++i) {
                    // One relaxed load per pixel (a tile can take seconds at high spp); the
                    // rest is skipped, and Interrupted thrown below.
                    if (interrupted()) return;
                    Vec3 sum, sum_clamped;
                    for (int k = 0; k < spp; ++k) {
                        double ox = 0.5, oy = 0.5;
                        if (spp > 1) {
                            const std::uint64_t seed = mix((static_cast<std::uint64_t>(j) * w + i) * 1024 + k);
                            ox = ((k % sx_n) + unit(seed)) / sx_n;
                            oy = ((k / sx_n) + unit(mix(seed))) / sy_n;
                        }
                        const Ray ray = cam.ray(i, j, ox, oy);
                        ++rays;
                        SurfaceHit hit;
                        Vec3 c = s.background;
                        if (opt.layered)
                            c = trace_layers(rs, ray, spread, counters);
                        else if (rs.intersect(ray, 0.0, kInfinity, hit))
                            c = opt.shader ? opt.shader(ray, hit, counters) : shade(rs, ray, hit, counters);
                        sum += c;
                        sum_clamped += Vec3{std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0),
                                            std::clamp(c.z, 0.0, 1.0)};
                    }
                    const std::size_t px = (static_cast<std::size_t>(j) * w + i) * 3;
                    for (std::size_t ch = 0; ch < 3; ++ch) {
                        out.radiance.rgb[px + ch] = static_cast<float>(sum[ch] / spp);
                        out.display.rgb[px + ch] = to_byte(sum_clamped[ch] / spp);
                    }
                }
            }
            primary.fetch_add(rays, std::memory_order_relaxed);
            shadow.fetch_add(counters.shadow_rays, std::memory_order_relaxed);
            visits.fetch_add(lattice_visits_this_thread() - visits0, std::memory_order_relaxed);
            bar.add(1);
        }
    });
    bar.finish();
    throw_if_interrupted();
    out.stats.render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    out.stats.primary_rays = primary.load();
    out.stats.shadow_rays = shadow.load();
    out.stats.lattice_visits = visits.load();
    out.stats.threads = tbb::this_task_arena::max_concurrency();
    return out;
}

}  // namespace lat
