// lattice render SCENE.json -o OUT.png [--threads N] [--spp N] [--stats FILE.json] [--mode M]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "distributed/job.h"
#include "distributed/timeline.h"
#include "io/image.h"
#include "render/render_request.h"
#include "scene/scene_loader.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/memory.h"
#include "util/progress.h"

namespace lat::cli {
namespace {

void write_image(const std::string& path, ImageFormat format, const RenderOutput& out) {
    switch (format) {
        case ImageFormat::png: write_png(path, out.display); break;
        case ImageFormat::pfm: write_pfm(path, out.radiance); break;
        case ImageFormat::exr: write_exr(path, out.radiance); break;
    }
}

void print_summary(const RenderRequest& a, const Scene& scene, const ModeResult& r, const RenderTimings& t) {
    const SceneLattices& lattices = r.lattices;
    const RenderStats& st = r.out.stats;
    for (const PrimitiveAnswer& p : lattices.answers)
        std::fprintf(stderr, "lattice: %s: %s\n", p.where.c_str(),
                     answer_text(p, a.lattice_filter()).c_str());
    if (!lattices.paths.empty() || (a.answers_instances() && a.render_mode() != RenderMode::kExact))
        std::fprintf(stderr, "lattice: %zu table%s read (%s, %s hits), %d built in %.1f s, %llu table visits\n",
                     lattices.paths.size(), lattices.paths.size() == 1 ? "" : "s",
                     human_bytes(static_cast<double>(lattices.table_bytes)).c_str(),
                     std::to_string(lattices.table_entries).c_str(), lattices.built,
                     lattices.build_seconds, static_cast<unsigned long long>(st.count(stats::Counter::kLatticeVisits)));
    for (const SceneLattices::Built& b : lattices.builds) {
        std::string what = "lattice: built " + b.primitive + "'s table at sigma^-1 = " + std::to_string(b.sigma_inv);
        if (b.coverage_rays > 0) what += ", " + std::to_string(b.coverage_rays) + " sub-rays a pair";
        std::fprintf(stderr, "%s, in %.1f s", what.c_str(), b.seconds);
        if (b.coverage_rays > 0)
            std::fprintf(stderr, " (estimated %.1f minutes of one core)", b.estimated_cpu_seconds / 60);
        std::fprintf(stderr, "\n");
    }
    if (const auto& m = r.shadow_maps) {
        std::string sizes;
        for (const int n : m->sizes)
            if (n > 0) sizes += (sizes.empty() ? "" : ", ") + std::to_string(n);
        std::fprintf(stderr,
                     "lattice: instances' shadows from deep shadow maps of %zu of %zu lights "
                     "(%s texels a side, %llu of %llu tiles traced, %s); %s\n",
                     m->lights_mapped, m->lights, sizes.empty() ? "no" : sizes.c_str(),
                     static_cast<unsigned long long>(m->tiles_traced),
                     static_cast<unsigned long long>(m->tiles),
                     human_bytes(static_cast<double>(m->bytes)).c_str(),
                     m->lights_mapped == m->lights
                         ? "other shadows by shadow rays"
                         : "the other lights lie among the instances and cast shadow rays");
    }
    if (a.answers_instances() && lattices.answers.empty())
        std::fprintf(stderr, "lattice: note: the scene has no instances of a primitive: every object is traced exactly\n");
    for (const std::string& note : lattices.notes) std::fprintf(stderr, "lattice: note: %s\n", note.c_str());
    for (const std::string& note : a.notes) std::fprintf(stderr, "lattice: note: %s\n", note.c_str());
    if (st.ranks.size() > 1)
        std::fprintf(stderr, "lattice: render spread over %zu MPI ranks (tiles per rank:%s)\n",
                     st.ranks.size(), [&] {
                         std::string tiles;
                         for (const RankStats& rs : st.ranks) tiles += " " + std::to_string(rs.tiles);
                         return tiles;
                     }().c_str());
    std::fprintf(stderr,
                 "lattice: %s %dx%d, %d spp (%s), %s mode%s: render %.1f ms on %d threads, "
                 "%llu primary + %llu shadow rays, %.2f M rays/s (total %.1f ms, peak %.1f MB)\n",
                 a.output.c_str(), scene.camera.width, scene.camera.height, std::max(1, a.spp),
                 std::string(st.sampler).c_str(), a.mode.c_str(),
                 a.render_mode() == RenderMode::kExact && a.footprint_on() ? " with footprint filtering" : "",
                 st.render_ms, st.threads,
                 static_cast<unsigned long long>(st.primary_rays),
                 static_cast<unsigned long long>(st.shadow_rays), mrays_per_s(st), t.written,
                 static_cast<double>(peak_rss_bytes()) / (1 << 20));
}

int run_render(const RenderRequest& a) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    auto since_start = [&] {
        return std::chrono::duration<double, std::milli>(clock::now() - start).count();
    };
    // Everything the user can get wrong is checked before the (possibly long) render; in an MPI
    // job every rank loads the scene, and a mistake found on any rank ends them all.
    ImageFormat format{};
    Scene scene;
    dist::agree([&] {
        format = image_format_for(a.output);
        if (dist::is_root()) {  // only rank 0 writes
            check_writable(a.output);
            if (!a.stats.empty()) check_writable(a.stats);
        }
        scene = load_scene(a.scene, !a.quiet && dist::is_root() && ProgressBar::stderr_is_terminal());
        check_render_budget(scene.camera, a.spp, a.scene);
    });
    agree_on_scene(a.scene);
    dist::mark(dist::Step::kLoaded);
    // A mode that is not dealt across ranks renders on rank 0 alone.
    const bool across = dist::distributed() && mode_description(a.render_mode()).spreads_over_ranks;
    if (!across && !dist::is_root()) return 0;

    RenderTimings t;
    const ThreadLimit limit(a.threads);
    const bool progress = !a.quiet && dist::is_root() && ProgressBar::stderr_is_terminal();
    t.loaded = since_start();
    t.loaded_cpu = cpu_seconds() * 1e3;
    ModeSettings settings = mode_settings(a);
    settings.progress = progress;
    settings.across_ranks = across;
    // From the render on a signal stops it at the next tile and removes our temporaries.
    settings.before_render = [] { install_interrupt_handlers(); };
    const ModeResult r = render_in_mode(scene, a.render_mode(), settings);
    if (!dist::is_root()) return 0;
    const RenderOutput& out = r.out;
    write_image(a.output, format, out);
    t.written = since_start();

    if (!a.quiet) print_summary(a, scene, r, t);
    if (!a.stats.empty()) write_json_file(a.stats, render_stats_json(a, scene, r, t));
    return 0;
}

}  // namespace

Command add_render_command(CLI::App& parent) {
    auto args = std::make_shared<RenderRequest>();
    Command c;
    c.app = parent.add_subcommand("render", "Ray trace a scene to an image (PNG, PFM or EXR)");
    add_entries(*c.app, render_option_entries(), *args);
    c.across_ranks = true;
    c.run = [args, app = c.app] {
        settle_request(*args, [&](std::string_view name) {
            return app->get_option(std::string(name))->count() > 0;
        });
        return run_render(*args);
    };
    return c;
}

}  // namespace lat::cli
