// Lattices: rasterizing the Plate 3 hair at sigma^-1 = 1, 2, 4 (time, pairs/s, table bytes),
// and Plates 4 and 5 rendered in lattice and exact mode at 1 and 2 threads in the same run.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <memory>
#include <string>

#include "lattice/boundary_grid.h"
#include "lattice/cache/table_build.h"
#include "lattice/cache/table_cache.h"
#include "lattice/encoding.h"
#include "render/modes/integrators.h"
#include "render/modes/scene_lattices.h"
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
    const lat::TablePlan plan = lat::plan_table(hair, spec, scene.file);
    for (auto _ : state) b = lat::build_table_file(plan, path, false);
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

// Lookups: tables of the hair built in memory once per (encoding, sigma^-1); pairs drawn at
// random among all valid pairs, or coherent (one entry point, exits along rows of a face).
struct BuiltTable {
    lat::ByteBuffer payload;
    std::unique_ptr<lat::LatticeTable> table;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> random, coherent;
};

BuiltTable& built_table(const std::string& encoding, int k) {
    static std::map<std::pair<std::string, int>, BuiltTable> cache;
    auto key = std::make_pair(encoding, k);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    static const lat::Scene scene = lat::load_scene(example("plate3-hair-closeup"));
    const lat::Primitive& hair = scene.primitives.at(0);
    BuiltTable& b = cache[key];
    const lat::TableContext ctx{{7 * k, 7 * k, 20 * k}, 1.0 / k, 1.0, hair.shape.get()};
    lat::RasterizeOptions ro;
    const lat::Encoding& e = lat::find_encoding(encoding);
    ro.keep_hits = e.needs_hits;
    const lat::RasterizeResult r = lat::rasterize(ctx, ro);
    b.payload = e.build(r.raw, ctx, {});
    b.table = e.open(b.payload.data(), b.payload.size(), r.hits, ctx);
    const lat::BoundaryGrid grid(ctx.cells);
    std::mt19937 rng(1);
    std::uniform_int_distribution<std::uint32_t> pick(0, grid.count() - 1);
    while (b.random.size() < (1u << 20)) {
        const std::uint32_t x = pick(rng), y = pick(rng);
        if (x != y && lat::BoundaryGrid::valid_pair(grid.faces(grid.point(x)), grid.faces(grid.point(y))))
            b.random.push_back({x, y});
    }
    while (b.coherent.size() < (1u << 20)) {
        const std::uint32_t x = pick(rng);
        const lat::GridPoint p = grid.point(x);
        // Exits along the face opposite to one of x's faces, row by row.
        const int axis = (__builtin_ctz(grid.faces(p)) >> 1);
        const int level = p[axis] == 0 ? ctx.cells[static_cast<std::size_t>(axis)] : 0;
        const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
        for (int v = 0; v <= ctx.cells[static_cast<std::size_t>(va)]; ++v)
            for (int u = 0; u <= ctx.cells[static_cast<std::size_t>(ua)]; ++u) {
                lat::GridPoint q;
                q[axis] = level, q[ua] = u, q[va] = v;
                b.coherent.push_back({x, grid.id(q)});
            }
    }
    return b;
}

void BM_Lookup(benchmark::State& state, const std::string& encoding, int k, bool coherent) {
    BuiltTable& b = built_table(encoding, k);
    const auto& pairs = coherent ? b.coherent : b.random;
    std::size_t i = 0, hits = 0;
    for (auto _ : state) {
        const auto [x, y] = pairs[i++ & (pairs.size() - 1)];
        lat::TableHit h;
        lat::CandidateList c;
        // Candidate tables answer the renderer with their lists; hit tables with the hit.
        hits += b.table->kind() == lat::LatticeTable::Kind::kCandidates ? b.table->candidates(x, y, c)
                                                                          : b.table->lookup(x, y, h);
    }
    state.counters["hit_share"] = double(hits) / double(state.iterations());
    state.counters["bytes_per_hit"] = double(b.payload.size()) / double(b.table->entries());
}

int register_lookups() {
    for (const lat::Encoding* e : lat::encodings())
        for (int k : {1, 2, 4})
            for (bool coherent : {false, true})
                benchmark::RegisterBenchmark(("lookup/" + std::string(e->name) + "/sigma_inv:" +
                                              std::to_string(k) + (coherent ? "/coherent" : "/random"))
                                                 .c_str(),
                                             BM_Lookup, std::string(e->name), k, coherent)
                    ->Unit(benchmark::kNanosecond);
    return 0;
}
const int lookups_registered = register_lookups();

// Blends of the smooth filter, as FilteredLatticeShape::blend makes them: the 5 pairs on a
// path through one cell of the 4-D (entry u, v; exit u, v) grid of two faces, each step moving
// one coordinate by one; located, then read (locate_coverage, coverage_at). Cells drawn at
// random among those whose blend finds at least one stored pair (rays near the hair), over the
// Plate 4 hair's coverage tables, taken from the table cache ($LATTICE_CACHE_DIR if set: the
// tables at sigma^-1 = 4 take a minute or two to build).
struct BlendTable {
    std::shared_ptr<const lat::LatticeTable> table;
    std::vector<std::array<std::uint32_t, 10>> blends;  // a[5], then b[5]
};

BlendTable& blend_table(int k) {
    static std::map<int, BlendTable> cache;
    if (auto it = cache.find(k); it != cache.end()) return it->second;
    static const lat::Scene scene = lat::load_scene(example("plate4-fuzzy-sphere-1000"));
    lat::TableSpec spec;
    spec.sigma_inv = k;
    spec.encoding = "coverage";
    const lat::TablePlan plan = lat::plan_table(scene.primitives.at(0), spec, scene.file);
    const char* env = std::getenv("LATTICE_CACHE_DIR");
    const lat::TableCache tables(env && *env ? env : cache_dir(), true);
    BlendTable& b = cache[k];
    b.table = tables.get(plan, false).table;
    const lat::BoundaryGrid grid(plan.context.cells);
    const auto& n = plan.context.cells;
    std::mt19937 rng(7);
    while (b.blends.size() < (1u << 18)) {
        const int f = static_cast<int>(rng() % 6), g = static_cast<int>(rng() % 6);
        if (f == g) continue;
        int c[2][3];
        int axis[4];
        for (int e = 0; e < 2; ++e) {
            const int face = e ? g : f, ax = face / 2;
            c[e][ax] = face % 2 ? n[static_cast<std::size_t>(ax)] : 0;
            for (int j = 1; j <= 2; ++j) {
                const int a = (ax + j) % 3;
                c[e][a] = static_cast<int>(rng() % static_cast<unsigned>(n[static_cast<std::size_t>(a)]));
                axis[2 * e + j - 1] = a;
            }
        }
        int order[4] = {0, 1, 2, 3};
        std::shuffle(order, order + 4, rng);
        std::array<std::uint32_t, 10> bl{};
        for (int step = 0; step <= 4; ++step) {
            bl[static_cast<std::size_t>(step)] = grid.id({c[0][0], c[0][1], c[0][2]});
            bl[static_cast<std::size_t>(5 + step)] = grid.id({c[1][0], c[1][1], c[1][2]});
            if (step < 4) ++c[order[step] / 2][axis[order[step]]];
        }
        lat::CoverageHit h[5];
        bool found[5];
        b.table->coverage_many(bl.data(), bl.data() + 5, 5, h, found, false);
        if (std::count(found, found + 5, true)) b.blends.push_back(bl);
    }
    return b;
}

// chained: each blend's index depends on the previous one's answer (a ray's next visit waits
// for its last one, whose sheet decides where its traversal goes), so that the processor cannot
// overlap one blend's cache misses with the next one's: latency, not throughput.
void BM_Blend(benchmark::State& state, bool chained) {
    BlendTable& b = blend_table(static_cast<int>(state.range(0)));
    std::size_t i = 0, found_pairs = 0;
    for (auto _ : state) {
        const auto& bl = b.blends[i & (b.blends.size() - 1)];
        lat::CoverageHit h[5];
        bool found[5];
        std::uint64_t ref[5];
        b.table->locate_coverage(bl.data(), bl.data() + 5, 5, ref);
        b.table->coverage_at(ref, 5, h, found, true);
        const auto n = static_cast<std::size_t>(std::count(found, found + 5, true));
        found_pairs += n;
        // n <= 5 and the alphas are at most 1: the step is 1 either way.
        i += chained ? 1 + (n > 5 || h[0].alpha > 1.5 || h[4].alpha > 1.5) : 1;
    }
    state.counters["found_per_blend"] = double(found_pairs) / double(state.iterations());
}
BENCHMARK_CAPTURE(BM_Blend, independent, false)->Arg(1)->Arg(2)->Arg(4)->ArgName("sigma_inv")->Unit(benchmark::kNanosecond);
BENCHMARK_CAPTURE(BM_Blend, chained, true)->Arg(1)->Arg(2)->Arg(4)->ArgName("sigma_inv")->Unit(benchmark::kNanosecond);

struct Prepared {
    lat::Scene scene;
    lat::SceneLattices lattices;
    std::unique_ptr<lat::TracedScene> exact, lattice;
};

Prepared& prepared(const std::string& plate) {
    static std::map<std::string, Prepared> cache;
    auto it = cache.find(plate);
    if (it != cache.end()) return it->second;
    Prepared& p = cache[plate];
    p.scene = lat::load_scene(example(plate));
    const lat::TableCache tables(cache_dir(), true);
    p.lattices = lat::scene_lattices(p.scene, tables, {}, false);
    p.exact = std::make_unique<lat::TracedScene>(p.scene);
    p.lattice = std::make_unique<lat::TracedScene>(
        p.scene, [&p](int i) { return p.lattices.shapes[static_cast<std::size_t>(i)]; });
    return p;
}

void BM_Render(benchmark::State& state, const std::string& plate, bool lattice) {
    Prepared& p = prepared(plate);
    const lat::TracedScene& rs = lattice ? *p.lattice : *p.exact;
    tbb::task_arena arena(static_cast<int>(state.range(0)));
    std::uint64_t rays = 0;
    for (auto _ : state) {
        lat::RenderOutput out;
        arena.execute([&] { out = lat::render_exact(rs, {}); });
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
