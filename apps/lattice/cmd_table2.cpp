// lattice table2 SCENE.json [-o DIR] [--spp N] [--truth-spp N] [--threads N] [--encodings a,b]
//     [--filter smooth] [--filter-spp 1] [--crop-size 96] [--crop-scale 3]
// The paper's Table 2 measured: the scene in every render mode (texture, particles, exact,
// lattice per encoding, a filtered lattice) against an exact render at many samples per pixel:
// fidelity (PSNR, SSIM, share of pixels off by more than 8/255), speed (render and
// preparation, separately) and space (bytes the mode adds to the scene without its
// instances); the images, one strip of them and one of magnified crops. docs/table2.md.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "common.h"
#include "io/image.h"
#include "io/image_compare.h"
#include "lattice/encoding.h"
#include "render/render_modes.h"
#include "render/baselines/scene_parts.h"
#include "table2_images.h"
#include "scene/scene_loader.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/memory.h"

namespace lat::cli {
namespace {

struct Table2Args {
    std::string scene;
    std::string out_dir = "table2-out";
    int spp = 16;
    int truth_spp = 256;
    int threads = 2;
    std::vector<std::string> encodings;
    std::string lattice_dir;
    TextureOptions texture;
    int shadow_map_size = ParticleOptions{}.shadow_map_size;
    std::string filter = "smooth";  // the filtered-lattice row; "none": no such row
    int filter_spp = 1;
    int crop_size = 96, crop_scale = 3;
};

// The paper's Table 2 row for the technique a mode stands for: its name, and its fidelity,
// speed and space as the paper rates them.
struct PaperRow {
    std::string_view technique, fidelity, speed, space;
};

PaperRow paper_row(RenderMode mode) {
    switch (mode) {
        case RenderMode::kExact: return {"full ray trace", "high", "slow", "medium"};
        case RenderMode::kLattice:
        case RenderMode::kAuto: return {"lattice", "high", "moderate", "large"};
        case RenderMode::kTexture: return {"texture mapping", "low", "very fast", "small"};
        case RenderMode::kParticles: return {"particle system", "medium", "fast", "small"};
    }
    return {};
}

struct Row {
    std::string name;  // the image's name: the mode, lattice-<encoding> or lattice-<encoding>-<filter>
    const ModeDescription* mode;
    PaperRow paper;
    int spp;
    ModeResult result;
    ImageDiffStats diff;
};

std::string fixed(double v, int digits) {
    if (std::isinf(v)) return "inf";
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", digits, v);
    return text;
}

std::string markdown(const Table2Args& a, const std::vector<Row>& rows, double truth_ms, double bare_ms,
                     const std::string& texture_unavailable) {
    std::ostringstream md;
    md << "Scene `" << a.scene << "`, against exact at " << a.truth_spp << " spp (" << fixed(truth_ms / 1000, 1)
       << " s, " << sampler_description(kTruthSampler).name << " sampler; the rows "
       << sampler_description(kDefaultSampler).name << "), " << a.threads
       << " threads. The base alone (exact, without its instances) renders in "
       << fixed(bare_ms, 0) << " ms at " << a.spp << " spp.\n\n";
    md << "| technique | mode | spp | paper: fidelity / speed / space | PSNR dB | SSIM | pixels off > 8 | "
          "render ms | build/bake ms | bytes added |\n";
    md << "| --- | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for (const Row& r : rows)
        md << "| " << r.paper.technique << " | " << r.name << " | " << r.spp << " | " << r.paper.fidelity
           << " / " << r.paper.speed << " / " << r.paper.space << " | " << fixed(r.diff.psnr_db, 2)
           << " | " << format_ssim(r.diff.ssim) << " | " << fixed(100 * r.diff.share_over_8, 2) << " % | "
           << fixed(r.result.out.stats.render_ms, 0) << " | "
           << fixed(r.result.prepare_ms + r.result.build_ms, 0) << " | "
           << human_bytes(static_cast<double>(r.result.bytes_added)) << " |\n";
    if (!texture_unavailable.empty())
        md << "\nTexture mapping not measured: " << texture_unavailable << "\n";
    return md.str();
}

nlohmann::json row_json(const Row& r) {
    auto num = [](double v) { return std::isinf(v) ? nlohmann::json("inf") : nlohmann::json(v); };
    return {{"name", r.name},
            {"mode", r.mode->name},
            {"paper", {{"technique", r.paper.technique},
                       {"fidelity", r.paper.fidelity},
                       {"speed", r.paper.speed},
                       {"space", r.paper.space}}},
            {"image", r.name + ".png"},
            {"spp", r.spp},
            {"sampler", r.result.out.stats.sampler},
            {"psnr_db", num(r.diff.psnr_db)},
            {"ssim", std::isnan(r.diff.ssim) ? nlohmann::json(nullptr) : nlohmann::json(r.diff.ssim)},
            {"share_over_8", r.diff.share_over_8},
            {"render_ms", r.result.out.stats.render_ms},
            {"prepare_ms", r.result.prepare_ms},
            {"build_ms", r.result.build_ms},
            {"bytes_added", r.result.bytes_added},
            {"primary_rays", r.result.out.stats.primary_rays},
            {"shadow_rays", r.result.out.stats.shadow_rays}};
}

int run_table2(const Table2Args& a) {
    namespace fs = std::filesystem;
    // Mistakes first: the encodings, the scene, the output directory.
    std::vector<std::string> encodings = a.encodings;
    if (encodings.empty())
        for (const Encoding* e : lat::encodings()) encodings.emplace_back(e->name);
    for (const std::string& e : encodings) find_encoding(e);
    const LatticeFilter filter = lattice_filters().at(a.filter);
    const std::string filtered_encoding = filter == LatticeFilter::kNone ? "" : std::string(coverage_encoding().name);
    const Scene scene = load_scene(a.scene);
    check_render_budget(scene.camera, std::max(a.spp, a.truth_spp), a.scene);
    // The texture mode needs a base surface it can map; without one its row is left out (and
    // said why), as a texture artist would have no map to paint: the other columns still stand.
    std::string texture_unavailable;
    try {
        texture_base(scene);
    } catch (const InputError& e) {
        texture_unavailable = e.what();
    }
    make_particles(scene);  // the particle mode chains
    std::vector<std::string> planned = encodings;
    if (!filtered_encoding.empty()) planned.push_back(filtered_encoding);
    for (const std::string& e : planned) {  // and the lattice mode tables of every encoding
        TableSpec spec;
        spec.encoding = e;
        for (const std::size_t i : instance_objects(scene))
            plan_table(scene.primitives[static_cast<std::size_t>(scene.primitive_of(i))], spec, scene.file);
    }
    std::error_code ec;
    fs::create_directories(a.out_dir, ec);
    if (ec) throw InputError(a.out_dir + ": cannot create the output directory: " + ec.message());
    const std::string md_path = (fs::path(a.out_dir) / "table2.md").string();
    check_writable(md_path);
    const ThreadLimit limit(a.threads);

    ModeSettings settings;
    settings.lattice_dir = a.lattice_dir;
    settings.texture = a.texture;
    settings.shadow_map_size = a.shadow_map_size;
    settings.spp = a.truth_spp;
    // Independent random points: a truth from the rows' own sampler could share their samples.
    settings.sampler = kTruthSampler;
    std::fprintf(stderr, "table2: truth, exact at %d spp\n", a.truth_spp);
    const ModeResult truth = render_in_mode(scene, RenderMode::kExact, settings);
    write_png((fs::path(a.out_dir) / "truth.png").string(), truth.out.display);

    settings.spp = a.spp;
    settings.sampler = kDefaultSampler;
    std::fprintf(stderr, "table2: the base alone\n");
    const double bare_ms = render_in_mode(base_scene(scene), RenderMode::kExact, settings).out.stats.render_ms;
    std::vector<Row> rows;
    auto run = [&](const std::string& name, RenderMode mode) {
        std::fprintf(stderr, "table2: %s\n", name.c_str());
        Row r{name, &mode_description(mode), paper_row(mode), settings.spp, render_in_mode(scene, mode, settings), {}};
        r.diff = compare_images(r.result.out.display, truth.out.display);
        write_png((fs::path(a.out_dir) / (name + ".png")).string(), r.result.out.display);
        rows.push_back(std::move(r));
    };
    if (texture_unavailable.empty()) {
        run("texture", RenderMode::kTexture);
    } else {
        std::fprintf(stderr, "table2: texture: not measured: %s\n", texture_unavailable.c_str());
    }
    run("particles", RenderMode::kParticles);
    run("exact", RenderMode::kExact);
    for (const std::string& e : encodings) {
        settings.spec.encoding = e;
        run("lattice-" + e, RenderMode::kLattice);
    }
    if (!filtered_encoding.empty()) {  // filtering stands in for supersampling: its own spp
        settings.spec.encoding = filtered_encoding;
        settings.filtering.filter = filter;
        settings.filtering.lod = true;
        settings.spp = a.filter_spp;
        run("lattice-" + filtered_encoding + "-" + a.filter, RenderMode::kLattice);
        // The same filtering from each primitive's cheaper answer, and exact mode's own.
        run("auto-" + a.filter, RenderMode::kAuto);
        settings.footprint = true;
        run("exact-footprint", RenderMode::kExact);
    }

    std::vector<const Image8*> images{&truth.out.display};
    for (const Row& r : rows) images.push_back(&r.result.out.display);
    write_png((fs::path(a.out_dir) / "strip.png").string(), image_strip(images));
    const CropRegion crop = busiest_region(truth.out.display, a.crop_size);
    write_png((fs::path(a.out_dir) / "crops.png").string(), crop_strip(images, crop, a.crop_scale));

    std::string md = markdown(a, rows, truth.out.stats.render_ms, bare_ms, texture_unavailable);
    std::string order = "truth";
    for (const Row& r : rows) order += ", " + r.name;
    md += "\nStrip (`strip.png`), left to right: " + order + ". Crops (`crops.png`), the same order: " +
          std::to_string(crop.size) + " x " + std::to_string(crop.size) + " pixels from (" + std::to_string(crop.x) +
          ", " + std::to_string(crop.y) + ") (the truth's busiest square), " + std::to_string(a.crop_scale) +
          " x.\n";
    std::printf("%s", md.c_str());
    AtomicFile file(md_path);
    file.write(md.data(), md.size());
    file.commit();
    nlohmann::json j = {{"scene", a.scene},
                        {"spp", a.spp},
                        {"truth_spp", a.truth_spp},
                        {"truth_sampler", sampler_description(kTruthSampler).name},
                        {"threads", a.threads},
                        {"width", scene.camera.width},
                        {"height", scene.camera.height},
                        {"truth_render_ms", truth.out.stats.render_ms},
                        {"bare_base_render_ms", bare_ms},
                        {"texture_unavailable", texture_unavailable.empty() ? nlohmann::json(nullptr)
                                                                            : nlohmann::json(texture_unavailable)},
                        {"crop", {{"x", crop.x}, {"y", crop.y}, {"size", crop.size}, {"scale", a.crop_scale}}}};
    for (const Row& r : rows) j["rows"].push_back(row_json(r));
    write_json_file((fs::path(a.out_dir) / "table2.json").string(), j);
    return 0;
}

}  // namespace

Command add_table2_command(CLI::App& parent) {
    auto args = std::make_shared<Table2Args>();
    Command c;
    c.app = parent.add_subcommand(
        "table2", "The paper's Table 2 measured: every render mode against an exact many-sample render");
    c.app->add_option("scene", args->scene, "Scene file (JSON)")->required();
    c.app->add_option("-o,--output-dir", args->out_dir, "Directory for images, table2.md and table2.json");
    c.app->add_option("--spp", args->spp, "Samples per pixel of every mode")->check(CLI::Range(1, 65536));
    c.app->add_option("--truth-spp", args->truth_spp, "Samples per pixel of the exact ground truth")
        ->check(CLI::Range(1, 65536));
    c.app->add_option("--threads", args->threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 4096));
    c.app->add_option("--encodings", args->encodings, "Lattice encodings to measure (default: all)")
        ->delimiter(',');
    c.app->add_option("--lattice-dir", args->lattice_dir, "Directory of cached lattice tables");
    c.app->add_option("--texture-size", args->texture.width, "Texture mode: the map's width in texels")
        ->check(CLI::Range(2, 16384));
    c.app->add_option("--texture-subsamples", args->texture.subsamples, "Texture mode: rays per texel side")
        ->check(CLI::Range(1, 16));
    c.app->add_option("--shadow-map-size", args->shadow_map_size, "Particles mode: shadow map texels a side")
        ->check(CLI::Range(16, 16384));
    c.app->add_option("--filter", args->filter,
                      "The filtered rows: the coverage encoding with this filter in lattice and auto modes, and exact mode with footprint filtering (none: no such rows)")
        ->check(CLI::IsMember(lattice_filters()));
    c.app->add_option("--filter-spp", args->filter_spp,
                      "Samples per pixel of the filtered rows: lattice, auto and exact mode with footprint filtering (filtering stands in for supersampling)")
        ->check(CLI::Range(1, 65536));
    c.app->add_option("--crop-size", args->crop_size, "Side of the magnified crops, pixels")
        ->check(CLI::Range(8, 4096));
    c.app->add_option("--crop-scale", args->crop_scale, "Magnification of the crops")
        ->check(CLI::Range(1, 16));
    c.run = [args] { return run_table2(*args); };
    return c;
}

}  // namespace lat::cli
