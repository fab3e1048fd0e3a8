// Render time and rays/s of the paper's plates, per mode and thread count. Scene loading and
// acceleration-structure builds happen once, outside the timed loop (they are reported by
// `lattice render --stats` separately).
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <map>
#include <memory>
#include <string>

#include "render/modes/integrators.h"
#include "scene/scene_loader.h"

namespace {

const char* const kPlates[] = {"plate1-thistle-no-self-shading", "plate2-thistle",
                               "plate3-hair-closeup", "plate4-fuzzy-sphere-1000",
                               "plate5-fuzzy-sphere-5000"};

struct Prepared {
    lat::Scene scene;
    std::unique_ptr<lat::TracedScene> rs;
};

Prepared& prepared(const std::string& plate) {
    static std::map<std::string, Prepared> cache;
    auto it = cache.find(plate);
    if (it == cache.end()) {
        Prepared p;
        p.scene = lat::load_scene(std::string(LATTICE_SOURCE_DIR) + "/examples/" + plate + ".json");
        it = cache.emplace(plate, std::move(p)).first;
        it->second.rs = std::make_unique<lat::TracedScene>(it->second.scene);
    }
    return it->second;
}

void BM_RenderExact(benchmark::State& state, const std::string& plate) {
    Prepared& p = prepared(plate);
    tbb::task_arena arena(static_cast<int>(state.range(0)));
    std::uint64_t rays = 0;
    for (auto _ : state) {
        lat::RenderOutput out;
        arena.execute([&] { out = lat::render_exact(*p.rs, {}); });
        rays += out.stats.primary_rays + out.stats.shadow_rays;
        benchmark::DoNotOptimize(out.display.rgb.data());
    }
    state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
    state.counters["threads"] = static_cast<double>(state.range(0));
}

int register_all() {
    for (const char* plate : kPlates)
        benchmark::RegisterBenchmark((std::string("exact/") + plate).c_str(), BM_RenderExact,
                                     std::string(plate))
            ->Arg(1)
            ->Arg(2)
            ->ArgName("threads")
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->MinTime(1.0);
    return 0;
}
const int registered = register_all();

}  // namespace

BENCHMARK_MAIN();
