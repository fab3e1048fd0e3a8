// lattice render SCENE.json -o OUT.png [--threads N] [--spp N] [--stats FILE.json] [--mode M]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <vector>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "dist/job.h"
#include "dist/timeline.h"
#include "io/image.h"
#include "lattice/encoding.h"
#include "lattice/filtered_shape.h"
#include "render/render_modes.h"
#include "scene/scene_loader.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/memory.h"
#include "util/progress.h"

namespace lat::cli {
namespace {

// The option values, each said once: they both check the option and convert it.
std::map<std::string, RenderMode> mode_names() {
    std::map<std::string, RenderMode> m;
    for (const ModeDescription& d : render_modes()) m.emplace(std::string(d.name), d.mode);
    return m;
}
const std::map<std::string, RenderMode> kModes = mode_names();
std::map<std::string, SamplerKind> sampler_names() {
    std::map<std::string, SamplerKind> m;
    for (const SamplerDescription& d : samplers()) m.emplace(std::string(d.name), d.kind);
    return m;
}
const std::map<std::string, SamplerKind> kSamplers = sampler_names();
const std::map<std::string, bool> kOnOff{{"on", true}, {"off", false}};
const std::map<std::string, LatticeFilter>& kFilters = lattice_filters();
const std::map<std::string, Instancing> kInstancing{
    {"auto", Instancing::kAuto}, {"always", Instancing::kAlways}, {"never", Instancing::kNever}};

struct RenderArgs {
    std::string scene;
    std::string output;
    int threads = 0;
    int spp = 1;
    std::string sampler{sampler_description(kDefaultSampler).name};
    std::string stats;
    std::string mode = "exact";
    std::string lattice_dir;
    TableSpec spec;
    std::string instancing = "auto";
    TextureOptions texture;
    int shadow_map_size = ParticleOptions{}.shadow_map_size;
    std::string filter = "smooth";
    std::string lod = "on";
    double lod_budget = kLodBudgetMinutes;  // of one core
    std::string footprint = "off";
    bool quiet = false;
    // Options given that cannot act in this mode, said once each (option_notes).
    std::vector<std::string> notes;

    RenderMode render_mode() const { return kModes.at(mode); }
    // Whether instances are answered by lattices: tables or sub-rays (SceneLattices).
    bool answers_instances() const {
        return render_mode() == RenderMode::kLattice || render_mode() == RenderMode::kAuto ||
               (render_mode() == RenderMode::kExact && kOnOff.at(footprint));
    }
};

// The modes each mode-specific option acts in: a given option outside them gets a note (it
// would otherwise change nothing, silently).
struct OptionScope {
    const char* option;
    std::vector<RenderMode> modes;
};
const std::vector<OptionScope>& option_scopes() {
    using M = RenderMode;
    static const std::vector<OptionScope> scopes{
        {"--sigma-inv", {M::kLattice, M::kAuto}},     {"--encoding", {M::kLattice, M::kAuto}},
        {"--max-point-error", {M::kLattice, M::kAuto}}, {"--max-normal-error", {M::kLattice, M::kAuto}},
        {"--dense-normals", {M::kLattice, M::kAuto}}, {"--filter", {M::kLattice, M::kAuto}},
        {"--lod", {M::kLattice, M::kAuto}},           {"--lod-budget", {M::kLattice, M::kAuto}},
        {"--lattice-dir", {M::kLattice, M::kAuto}},   {"--footprint", {M::kExact}},
        {"--texture-size", {M::kTexture}},            {"--texture-subsamples", {M::kTexture}},
        {"--shadow-map-size", {M::kParticles}},
        {"--sampler", {M::kExact, M::kLattice, M::kAuto, M::kTexture}},
        {"--instancing", {M::kExact, M::kLattice, M::kAuto}},
    };
    return scopes;
}

// A note for each option given that cannot act here: outside its modes, or (--lod,
// --lod-budget) without what it refines.
std::vector<std::string> option_notes(const CLI::App& app, const RenderArgs& a) {
    std::vector<std::string> notes;
    const auto given = [&](const char* name) { return app.get_option(name)->count() > 0; };
    for (const OptionScope& s : option_scopes()) {
        if (!given(s.option) ||
            std::find(s.modes.begin(), s.modes.end(), a.render_mode()) != s.modes.end())
            continue;
        std::string where;
        for (const RenderMode m : s.modes)
            where += (where.empty() ? "" : ", ") + std::string(mode_description(m).name);
        notes.push_back(std::string(s.option) + " has no effect in " + a.mode +
                        " mode (it acts in: " + where + ")");
    }
    const bool tables = a.render_mode() == RenderMode::kLattice || a.render_mode() == RenderMode::kAuto;
    if (tables && kFilters.at(a.filter) == LatticeFilter::kNone && given("--lod"))
        notes.push_back("--lod has no effect with --filter none (point-sampled tables have one level)");
    if (tables && given("--lod-budget") &&
        (kFilters.at(a.filter) == LatticeFilter::kNone || !kOnOff.at(a.lod)))
        notes.push_back("--lod-budget has no effect without levels of detail (--lod on and a filter)");
    return notes;
}

// Wall-clock milestones of a render command, in milliseconds from its start.
struct Timings {
    double loaded = 0, written = 0;
};

void write_image(const std::string& path, ImageFormat format, const RenderOutput& out) {
    switch (format) {
        case ImageFormat::png: write_png(path, out.display); break;
        case ImageFormat::pfm: write_pfm(path, out.radiance); break;
        case ImageFormat::exr: write_exr(path, out.radiance); break;
    }
}

double mrays_per_s(const RenderStats& st) {
    const std::uint64_t rays = st.primary_rays + st.shadow_rays;
    return st.render_ms > 0 ? static_cast<double>(rays) / (st.render_ms * 1e3) : 0.0;
}

// "sigma^-1 = 1, 2, 4".
std::string levels_text(const std::vector<long long>& sigma_inv) {
    std::string text;
    for (const long long k : sigma_inv) text += (text.empty() ? "" : ", ") + std::to_string(k);
    return "sigma^-1 = " + text;
}

// How one primitive's instances were answered, in words.
std::string answer_text(const PrimitiveAnswer& p, LatticeFilter filter) {
    std::string text;
    switch (p.by) {
        case AnsweredBy::kTable:
            text = "point-sampled " + p.encoding + " table, " + levels_text(p.sigma_inv);
            break;
        case AnsweredBy::kFilteredTables:
            text = std::string(filter == LatticeFilter::kBox ? "box" : "smooth") + "-filtered " +
                   p.encoding + " table" + (p.sigma_inv.size() == 1 ? ", " : "s, ") +
                   levels_text(p.sigma_inv);
            break;
        case AnsweredBy::kSubRayCrossings:
            text = "its own crossings of " + std::to_string(kExactSubRays) + " x " +
                   std::to_string(kExactSubRays) + " sub-rays across each ray's footprint, no table";
            break;
        case AnsweredBy::kExact: text = "exact point samples, no table"; break;
    }
    return text + (p.why.empty() ? "" : " (" + p.why + ")");
}

void print_summary(const RenderArgs& a, const Scene& scene, const ModeResult& r, const Timings& t) {
    const SceneLattices& lattices = r.lattices;
    const RenderStats& st = r.out.stats;
    for (const PrimitiveAnswer& p : lattices.answers)
        std::fprintf(stderr, "lattice: %s: %s\n", p.where.c_str(),
                     answer_text(p, kFilters.at(a.filter)).c_str());
    if (!lattices.paths.empty() || (a.answers_instances() && a.render_mode() != RenderMode::kExact))
        std::fprintf(stderr, "lattice: %zu table%s read (%s, %s hits), %d built in %.1f s, %llu table visits\n",
                     lattices.paths.size(), lattices.paths.size() == 1 ? "" : "s",
                     human_bytes(static_cast<double>(lattices.table_bytes)).c_str(),
                     std::to_string(lattices.table_entries).c_str(), lattices.built,
                     lattices.build_seconds, static_cast<unsigned long long>(st.lattice_visits));
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
                 a.render_mode() == RenderMode::kExact && kOnOff.at(a.footprint) ? " with footprint filtering" : "",
                 st.render_ms, st.threads,
                 static_cast<unsigned long long>(st.primary_rays),
                 static_cast<unsigned long long>(st.shadow_rays), mrays_per_s(st), t.written,
                 static_cast<double>(peak_rss_bytes()) / (1 << 20));
}

nlohmann::json stats_json(const RenderArgs& a, const Scene& scene, const ModeResult& r,
                          const Timings& t) {
    const SceneLattices& lattices = r.lattices;
    const RenderStats& st = r.out.stats;
    nlohmann::json j;
    j["scene"] = a.scene;
    j["output"] = a.output;
    j["mode"] = a.mode;
    if (a.render_mode() == RenderMode::kExact) j["footprint"] = a.footprint;
    j["width"] = scene.camera.width;
    j["height"] = scene.camera.height;
    j["spp"] = std::max(1, a.spp);
    j["sampler"] = st.sampler;
    j["threads"] = st.threads;
    j["load_ms"] = t.loaded;
    j["build_ms"] = r.build_ms;
    j["prepare_ms"] = r.prepare_ms;
    j["bytes_added"] = r.bytes_added;
    if (a.answers_instances()) {
        // What answered, per primitive: the effective settings, not the requested ones.
        j["primitives"] = nlohmann::json::array();
        for (const PrimitiveAnswer& p : lattices.answers) {
            nlohmann::json e{{"primitive", p.primitive}, {"where", p.where},
                             {"answered_by", answer_name(p.by)}, {"how", answer_text(p, kFilters.at(a.filter))}};
            if (!p.encoding.empty()) e["encoding"] = p.encoding;
            if (p.by == AnsweredBy::kFilteredTables) e["filter"] = a.filter;
            if (!p.sigma_inv.empty()) e["sigma_inv"] = p.sigma_inv;
            if (p.by == AnsweredBy::kSubRayCrossings) e["sub_rays"] = kSubRays;
            if (!p.why.empty()) e["why"] = p.why;
            j["primitives"].push_back(std::move(e));
        }
        j["lattice_notes"] = lattices.notes;
        j["tables_ms"] = r.prepare_ms;
        j["tables_built"] = lattices.built;
        j["table_bytes"] = lattices.table_bytes;
        j["table_entries"] = lattices.table_entries;
        j["table_files"] = lattices.paths;
        j["table_visits"] = st.lattice_visits;
    }
    j["option_notes"] = a.notes;
    j["render_ms"] = st.render_ms;
    j["render_cpu_ms"] = st.cpu_ms;
    j["total_ms"] = t.written;
    j["primary_rays"] = st.primary_rays;
    j["shadow_rays"] = st.shadow_rays;
    j["rays_per_second"] = mrays_per_s(st) * 1e6;
    j["peak_memory_bytes"] = peak_rss_bytes();
    if (!st.ranks.empty()) {
        j["mpi_ranks"] = st.ranks.size();
        for (const RankStats& rs : st.ranks)
            j["ranks"].push_back({{"rank", rs.rank},
                                  {"host", rs.host},
                                  {"threads", rs.threads},
                                  {"tiles", rs.tiles},
                                  {"chunks", rs.chunks},
                                  {"render_ms", rs.render_ms},
                                  {"wait_ms", rs.wait_ms},
                                  {"cpu_ms", rs.cpu_ms},
                                  {"primary_rays", rs.primary_rays},
                                  {"shadow_rays", rs.shadow_rays},
                                  {"lattice_visits", rs.lattice_visits},
                                  {"peak_memory_bytes", rs.peak_memory_bytes},
                                  {"timeline_ms", timeline_json(rs.timeline)}});
    }
    return j;
}

int run_render(const RenderArgs& a) {
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
        scene = load_scene(a.scene);
        check_render_budget(scene.camera, a.spp, a.scene);
    });
    agree_on_scene(a.scene);
    dist::mark(dist::Step::kLoaded);
    // A mode that is not dealt across ranks renders on rank 0 alone.
    const bool across = dist::distributed() && mode_description(kModes.at(a.mode)).spreads_over_ranks;
    if (!across && !dist::is_root()) return 0;

    Timings t;
    const ThreadLimit limit(a.threads);
    const bool progress = !a.quiet && dist::is_root() && ProgressBar::stderr_is_terminal();
    t.loaded = since_start();
    ModeSettings settings;
    settings.spp = a.spp;
    settings.sampler = kSamplers.at(a.sampler);
    settings.progress = progress;
    settings.lattice_dir = a.lattice_dir;
    settings.spec = a.spec;
    settings.filtering.filter = kFilters.at(a.filter);
    settings.filtering.lod = kOnOff.at(a.lod);
    settings.filtering.max_work = lod_work(a.lod_budget);
    settings.footprint = kOnOff.at(a.footprint);
    settings.accel.instancing = kInstancing.at(a.instancing);
    settings.texture = a.texture;
    settings.shadow_map_size = a.shadow_map_size;
    settings.across_ranks = across;
    // From the render on a signal stops it at the next tile and removes our temporaries.
    settings.before_render = [] { install_interrupt_handlers(); };
    const ModeResult r = render_in_mode(scene, kModes.at(a.mode), settings);
    if (!dist::is_root()) return 0;
    const RenderOutput& out = r.out;
    write_image(a.output, format, out);
    t.written = since_start();

    if (!a.quiet) print_summary(a, scene, r, t);
    if (!a.stats.empty()) write_json_file(a.stats, stats_json(a, scene, r, t));
    return 0;
}

}  // namespace

Command add_render_command(CLI::App& parent) {
    auto args = std::make_shared<RenderArgs>();
    Command c;
    c.app = parent.add_subcommand("render", "Ray trace a scene to an image (PNG, PFM or EXR)");
    c.app->add_option("scene", args->scene, "Scene file (JSON)")->required();
    c.app->add_option("-o,--output", args->output, "Output image: .png, .pfm or .exr")->required();
    c.app->add_option("--threads", args->threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(0, 4096));
    c.app->add_option("--spp", args->spp, "Samples per pixel (1 = the pixel centre; see --sampler)")
        ->check(CLI::Range(1, 65536));
    std::string sampler_help = "Where a pixel's samples fall when --spp > 1 (exact, lattice and texture "
                               "modes; particles mode always takes the grid): ";
    for (const SamplerDescription& d : samplers())
        sampler_help += std::string(d.name) + (d.kind == kDefaultSampler ? " (the default)" : "") + ": " +
                        std::string(d.help) + "; ";
    sampler_help.resize(sampler_help.size() - 2);
    c.app->add_option("--sampler", args->sampler, sampler_help)->check(CLI::IsMember(kSamplers));
    c.app->add_option("--stats", args->stats, "Write timing and ray counts as JSON");
    std::string mode_help;
    for (const ModeDescription& d : render_modes())
        mode_help += (mode_help.empty() ? "" : "; ") + std::string(d.name) + ": " + std::string(d.help);
    c.app->add_option("--mode", args->mode, mode_help)->check(CLI::IsMember(kModes));
    c.app->add_option("--texture-size", args->texture.width,
                      "texture mode: the baked map's width in texels (height is half)")
        ->check(CLI::Range(2, 16384));
    c.app->add_option("--texture-subsamples", args->texture.subsamples,
                      "texture mode: rays per texel side when baking")
        ->check(CLI::Range(1, 16));
    c.app->add_option("--shadow-map-size", args->shadow_map_size,
                      "particles mode: texels on a side of each light's shadow map")
        ->check(CLI::Range(16, 16384));
    c.app->add_option("--lattice-dir", args->lattice_dir,
                      "Directory of cached lattice tables (default: $LATTICE_CACHE_DIR, "
                      "$XDG_CACHE_HOME/lattice or ~/.cache/lattice)");
    add_table_options(*c.app, args->spec);
    c.app->add_option("--filter", args->filter,
                      "lattice and auto modes: none (point-sampled tables, as rasterized), box (each pair's "
                      "coverage) or smooth (coverage blended over the neighbouring pairs, the "
                      "default unless --encoding names one without coverage); a filter uses the "
                      "coverage encoding")
        ->check(CLI::IsMember(kFilters));
    c.app->add_option("--lod", args->lod,
                      "lattice and auto modes with a filter: levels of detail, tables at sigma^-1 = "
                      "K, 2K, 4K as the pixels' footprints need, within --lod-budget (on); or K "
                      "alone (off)")
        ->check(CLI::IsMember(kOnOff));
    c.app->add_option("--lod-budget", args->lod_budget,
                      "lattice and auto modes, --lod on: levels of detail beyond K are built only "
                      "if each takes at most about this many minutes of one core (estimated from "
                      "its pairs and the primitive's cost); past it lattice mode reads the finest "
                      "level within it and auto mode answers the primitive by its sub-rays, and the "
                      "summary says so. A level in the cache is read whatever the budget")
        // Not CLI::Range: its comparisons let "nan" through.
        ->check([](const std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            return end != text.c_str() && *end == '\0' && std::isfinite(v) && v >= 0 && v <= 1e7
                       ? ""
                       : "a number of minutes from 0 to 1e7";
        })
        ->capture_default_str();
    c.app->add_option("--instancing", args->instancing,
                      "Multi-part objects as Embree instances (always), flattened into one "
                      "hierarchy (never), or flattened unless that would be huge (auto)")
        ->check(CLI::IsMember(kInstancing));
    c.app->add_option("--footprint", args->footprint,
                      "exact mode: each instance answered by its own crossings of " +
                          std::to_string(kExactSubRays) + " x " + std::to_string(kExactSubRays) +
                          " sub-rays across the ray's footprint (a pixel's, split by --spp), their "
                          "partial coverage composited front to back and shadowed per layer: "
                          "antialiased hair at 1 spp (on); or point samples (off)")
        ->check(CLI::IsMember(kOnOff))
        ->capture_default_str();
    c.app->add_flag("-q,--quiet", args->quiet, "No progress bar or summary line");
    c.across_ranks = true;
    c.run = [args, app = c.app] {
        // A filter needs coverage: unless an encoding was asked for, it takes the one with it;
        // an encoding without coverage asked for alone means its point-sampled table.
        const bool encoding_given = app->get_option("--encoding")->count() > 0;
        const bool filter_given = app->get_option("--filter")->count() > 0;
        if (encoding_given && !filter_given && !find_encoding(args->spec.encoding).coverage)
            args->filter = "none";
        if (kFilters.at(args->filter) != LatticeFilter::kNone && !encoding_given)
            args->spec.encoding = coverage_encoding().name;
        args->notes = option_notes(*app, *args);
        return run_render(*args);
    };
    return c;
}

}  // namespace lat::cli
