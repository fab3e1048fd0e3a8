// lattice rasterize SCENE.json --primitive NAME [--sigma-inv K] [-o FILE.lht] [--encoding E]
#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "distributed/job.h"
#include "distributed/timeline.h"
#include "lattice/cache/table_build.h"
#include "lattice/cache/table_cache.h"
#include "lattice/coverage.h"
#include "scene/scene_loader.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/progress.h"

namespace lat::cli {
namespace {

struct RasterizeArgs {
    std::string scene, primitive, output, lattice_dir, stats;
    TableSpec spec;
    int threads = 0;
    bool quiet = false;
};

// One rank's share of a rasterization spread across an MPI job.
struct RankShare {
    int rank = 0;
    dist::HostName host;
    std::uint64_t segments = 0, hits = 0;
    double seconds = 0, cpu_seconds = 0;
    std::uint64_t peak_memory_bytes = 0;
    dist::Timeline timeline{};
};

nlohmann::json rank_shares(const RasterizeResult& r, double build_cpu) {
    RankShare mine{dist::rank(), dist::HostName::here(), r.pairs_traced_here, r.hits_here, r.seconds,
                   build_cpu, peak_rss_bytes(), dist::timeline()};
    nlohmann::json j = nlohmann::json::array();
    for (const RankShare& s : dist::gather_values(mine))
        j.push_back({{"rank", s.rank},
                     {"host", s.host.text},
                     {"segments_traced", s.segments},
                     {"stored_hits", s.hits},
                     {"rasterize_seconds", s.seconds},
                     {"build_cpu_seconds", s.cpu_seconds},
                     {"peak_memory_bytes", s.peak_memory_bytes},
                     {"timeline_ms", timeline_json(s.timeline)}});
    return j;
}

int run_rasterize(const RasterizeArgs& a) {
    // In an MPI job every rank loads the scene and plans the table; all of them rasterize,
    // rank 0 encodes and writes.
    Scene scene;
    std::optional<TablePlan> plan;
    std::string path = a.output;
    dist::agree([&] {
        scene = load_scene(a.scene);
        plan = plan_table(find_primitive(scene, a.primitive), a.spec, a.scene);
    });
    agree_on_scene(a.scene);
    dist::mark(dist::Step::kLoaded);
    if (path.empty()) {
        const TableCache cache(a.lattice_dir.empty() ? default_cache_dir() : a.lattice_dir, true);
        path = cache.path_for(*plan);
    }
    const ThreadLimit limit(a.threads);
    const bool progress = !a.quiet && dist::is_root() && ProgressBar::stderr_is_terminal();
    const double cpu0 = cpu_seconds();
    const TableBuild b = build_table_file(*plan, path, progress, true);
    const double build_cpu = cpu_seconds() - cpu0;
    const nlohmann::json ranks = dist::distributed() ? rank_shares(b.raster, build_cpu) : nlohmann::json();
    if (!dist::is_root()) return 0;
    const Primitive* prim = plan->primitive;
    const RasterizeResult& r = b.raster;
    const double seconds = r.seconds + b.encode_seconds;
    const double per_entry = r.hits ? double(b.bytes) / double(r.hits) : 0.0;
    if (!a.quiet) {
        std::printf("%s: primitive '%s', %d x %d x %d cells (sigma %g, sigma^-1 %d)\n", path.c_str(),
                    prim->name.c_str(), b.header.cells[0], b.header.cells[1], b.header.cells[2],
                    b.header.sigma, a.spec.sigma_inv);
        std::printf("  N_lp %llu (eq. 2), %llu distinct segments traced\n",
                    static_cast<unsigned long long>(r.pairs_eq2),
                    static_cast<unsigned long long>(r.pairs_traced));
        std::printf("  N_ix %llu counted as N_lp, %llu stored; N_ix:N_lp %.3f\n",
                    static_cast<unsigned long long>(r.hits_counted),
                    static_cast<unsigned long long>(r.hits), double(r.hits_counted) / double(r.pairs_eq2));
        std::printf("  %.3f s (rasterize %.3f s, encode %.3f s), %.1f M pairs/s\n", seconds, r.seconds,
                    b.encode_seconds, double(r.pairs_eq2) / seconds / 1e6);
        std::printf("  table %s (%s), %llu bytes, %.2f bytes per stored hit\n", a.spec.encoding.c_str(),
                    human_bytes(double(b.bytes)).c_str(), static_cast<unsigned long long>(b.bytes),
                    per_entry);
    }
    if (!a.stats.empty()) {
        nlohmann::json j = {{"table", path},
                            {"primitive", prim->name},
                            {"sigma_inv", a.spec.sigma_inv},
                            {"encoding", a.spec.encoding},
                            {"cells", b.header.cells},
                            {"N_lp", r.pairs_eq2},
                            {"segments_traced", r.pairs_traced},
                            {"N_ix", r.hits_counted},
                            {"stored_hits", r.hits},
                            {"segment_tests", r.tests},
                            {"rasterize_seconds", r.seconds},
                            {"encode_seconds", b.encode_seconds},
                            {"pairs_per_second", double(r.pairs_eq2) / seconds},
                            {"table_bytes", b.bytes},
                            {"bytes_per_hit", per_entry},
                            {"peak_memory_bytes", peak_rss_bytes()}};
        // The CPU time of the build (check, rasterize, gather, encode, write; every rank's,
        // summed): its cost whatever else the machine runs.
        double cpu = build_cpu;
        if (!ranks.is_null()) {
            j["ranks"] = ranks;
            cpu = 0;
            for (const auto& rank : ranks) cpu += rank["build_cpu_seconds"].get<double>();
        }
        j["build_cpu_seconds"] = cpu;
        // A prefiltered table: its sub-rays a pair, and what the level budget (render
        // --lod-budget) estimated the build would take.
        if (plan->encoding->coverage && plan->context.primitive) {
            j["coverage_rays"] = plan->context.coverage_rays;
            j["estimated_build_cpu_seconds"] = coverage_cpu_seconds(plan->context);
            const CoverageWork w = coverage_work_parts(plan->context);
            j["estimate_pairs"] = w.pairs;
            j["estimate_part_tests"] = w.part_tests;
        }
        write_json_file(a.stats, j);
    }
    return 0;
}

}  // namespace

Command add_rasterize_command(CLI::App& parent) {
    auto args = std::make_shared<RasterizeArgs>();
    Command c;
    c.app = parent.add_subcommand("rasterize", "Build a primitive's lattice table (.lht)");
    c.app->add_option("scene", args->scene, "Scene file (JSON) that defines the primitive")->required();
    c.app->add_option("--primitive", args->primitive, "Name of the primitive")->required();
    add_table_options(*c.app, args->spec);
    c.app->add_option("-o,--output", args->output,
                      "Table file (default: the render cache, where `render --mode lattice` finds it)");
    c.app->add_option("--lattice-dir", args->lattice_dir, "Cache directory for the default output");
    c.app->add_option("--stats", args->stats, "Write the figures as JSON");
    c.app->add_option("--threads", args->threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(0, 4096));
    c.app->add_flag("-q,--quiet", args->quiet, "No progress bar or summary");
    c.across_ranks = true;
    c.run = [args] { return run_rasterize(*args); };
    return c;
}

}  // namespace lat::cli
