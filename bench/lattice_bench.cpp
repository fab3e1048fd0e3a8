// Lattices: rasterizing the Plate 3 hair at sigma^-1 = 1, 2, 4 (time, pairs/s, table bytes),
// and Plates 4 and 5 rendered in lattice and exact mode at 1 and 2 threads in the same run.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "lattice/encodings.h"
#include "render/renderer.h"
#include "scene/lattice_tables.h"
#include "scene/scene_loader.h"

namespace {

std::string example(const std::string& name) {
    return std::string(LATTICE_SOURCE_DIR) + "/examples/" + name + ".json";
}

std::string cache_dir() {
    static const std::string dir = [] {
        const auto d = std::filesystem::temp_directory_path() / "lattice-bench-cache";
        std::filesystem::create_directories(d);
        return d.string();
    }();
    return dir;
}

void BM_Rasterize(benchmark::State& state) {
    const lat::Scene scene = lat::load_scene(example("plate3-hair-closeup"));
    const lat::Primitive& hair = scene.primitives.at(0);
    const int k = static_cast<int>(state.range(0));
    const std::string path = cache_dir() + "/bench-hair.lht";
    lat::TableBuild b;
    lat::TableSpec spec;
    spec.sigma_inv = k;
    for (auto _ : state) b = lat::build_table_file(hair, spec, path, scene.file, false);
    const double pairs = static_cast<double>(b.raster.pairs_eq2);
    state.counters["pairs"] = pairs;
    state.counters["stored_hits"] = static_cast<double>(b.raster.hits);
    state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["trace_pairs_per_s"] = pairs / b.raster.seconds;
    state.counters["table_bytes"] = static_cast<double>(b.bytes);
    state.counters["bytes_per_hit"] = static_cast<double>(b.bytes) / static_cast<double>(b.raster.hits);
    std::filesystem::remove(path);
}
BENCHMARK(BM_Rasterize)->Arg(1)->Arg(2)->Arg(4)->ArgName("sigma_inv")->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(3);

struct Prepared {
    lat::Scene scene;
    lat::SceneLattices lattices;
    std::unique_ptr<lat::RenderScene> exact, lattice;
};

Prepared& prepared(const std::string& plate) {
    static std::map<std::string, Prepared> cache;
    auto it = cache.find(plate);
    if (it != cache.end()) return it->second;
    Prepared& p = cache[plate];
    p.scene = lat::load_scene(example(plate));
    const lat::TableCache tables(cache_dir(), true);
    p.lattices = lat::scene_lattices(p.scene, tables, {}, false);
    p.exact = std::make_unique<lat::RenderScene>(p.scene);
    p.lattice = std::make_unique<lat::RenderScene>(
        p.scene, [&p](int i) { return p.lattices.shapes[static_cast<std::size_t>(i)]; });
    return p;
}

void BM_Render(benchmark::State& state, const std::string& plate, bool lattice) {
    Prepared& p = prepared(plate);
    const lat::RenderScene& rs = lattice ? *p.lattice : *p.exact;
    tbb::task_arena arena(static_cast<int>(state.range(0)));
    std::uint64_t rays = 0;
    for (auto _ : state) {
        lat::RenderOutput out;
        arena.execute([&] { out = lat::render_image(rs, {}); });
        rays += out.stats.primary_rays + out.stats.shadow_rays;
    }
    state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
    if (lattice) state.counters["table_bytes"] = static_cast<double>(p.lattices.table_bytes);
}

int register_renders() {
    for (const char* plate : {"plate4-fuzzy-sphere-1000", "plate5-fuzzy-sphere-5000"})
        for (const bool lattice : {true, false})
            benchmark::RegisterBenchmark((std::string(lattice ? "lattice/" : "exact/") + plate).c_str(),
                                         BM_Render, std::string(plate), lattice)
                ->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kMillisecond)->UseRealTime()
                ->MinTime(1.0);
    return 0;
}
const int registered = register_renders();

}  // namespace

BENCHMARK_MAIN();
