// reftrace SCENE.json -o OUT.png [--threads N] [--size WxH] [--compare IMG.png [--diff D.png]]
//          [--explain N] [--trace I,J]
// Renders a "lattice-reference/1" scene with the independent reference tracer (tests/reference)
// and optionally compares the result with another renderer's PNG of the same view, listing the
// worst pixels with what the reference ray found there.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "io/image.h"
#include "io/image_compare.h"
#include "reference_tracer.h"

namespace {

lat::Image8 to_lat(const reftrace::Image& img) {
    return {img.width, img.height, img.rgb};
}

void print_trace(const reftrace::Scene& scene, int w, int h, int i, int j) {
    const reftrace::PixelTrace t = reftrace::trace_pixel(scene, w, h, i, j);
    std::printf("  ref (%d,%d): ", i, j);
    if (!t.hit) {
        std::printf("background\n");
        return;
    }
    std::printf("object %d component %d t %.9Lf p (%.6Lf %.6Lf %.6Lf) n (%.6Lf %.6Lf %.6Lf) lights",
                t.object, t.component, t.t, t.p.x, t.p.y, t.p.z, t.n.x, t.n.y, t.n.z);
    for (char seen : t.light_seen) std::printf(" %s", seen ? "seen" : "hidden");
    std::printf(" colour (%.5Lf %.5Lf %.5Lf)\n", t.color.x, t.color.y, t.color.z);
}

// The n pixels with the largest channel error, worst first, with both colours.
void explain(const reftrace::Scene& scene, const lat::Image8& ref, const lat::Image8& other,
             int n) {
    struct Px {
        int err, i, j;
    };
    std::vector<Px> px;
    for (int j = 0; j < ref.height; ++j) {
        for (int i = 0; i < ref.width; ++i) {
            const std::size_t k = 3 * (static_cast<std::size_t>(j) * ref.width + i);
            int e = 0;
            for (int c = 0; c < 3; ++c)
                e = std::max(e, std::abs(ref.rgb[k + c] - other.rgb[k + c]));
            if (e > 0) px.push_back({e, i, j});
        }
    }
    std::stable_sort(px.begin(), px.end(), [](const Px& a, const Px& b) { return a.err > b.err; });
    px.resize(std::min<std::size_t>(px.size(), static_cast<std::size_t>(n)));
    for (const Px& p : px) {
        const std::size_t k = 3 * (static_cast<std::size_t>(p.j) * ref.width + p.i);
        std::printf("pixel (%d,%d) error %d: ref %d %d %d, other %d %d %d\n", p.i, p.j, p.err,
                    ref.rgb[k], ref.rgb[k + 1], ref.rgb[k + 2], other.rgb[k], other.rgb[k + 1],
                    other.rgb[k + 2]);
        print_trace(scene, ref.width, ref.height, p.i, p.j);
    }
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Render a lattice-reference/1 scene with the independent reference tracer"};
    std::string scene_path, output, compare, diff, size, trace;
    int threads = 0, explain_n = 0;
    app.add_option("scene", scene_path, "scene file")->required();
    app.add_option("-o,--output", output, "PNG to write")->required();
    app.add_option("--threads", threads, "threads (0: all)");
    app.add_option("--size", size, "render the same view at WxH instead");
    app.add_option("--compare", compare, "PNG of the same view to compare with");
    app.add_option("--diff", diff, "heat-map of the differences (with --compare)");
    app.add_option("--explain", explain_n, "list the N worst pixels (with --compare)");
    app.add_option("--trace", trace, "print what the ray of pixel I,J finds");
    CLI11_PARSE(app, argc, argv);

    try {
        const reftrace::Scene scene = reftrace::load_scene(scene_path);
        int w = scene.camera.width, h = scene.camera.height;
        if (!size.empty() && std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2) {
            std::fprintf(stderr, "--size: expected WxH\n");
            return 2;
        }
        if (!trace.empty()) {
            int i = 0, j = 0;
            if (std::sscanf(trace.c_str(), "%d,%d", &i, &j) != 2) {
                std::fprintf(stderr, "--trace: expected I,J\n");
                return 2;
            }
            print_trace(scene, w, h, i, j);
        }
        const auto t0 = std::chrono::steady_clock::now();
        const lat::Image8 ref = to_lat(reftrace::render_resized(scene, w, h, threads));
        const double secs =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        lat::write_png(output, ref);
        std::printf("reference: %dx%d in %.2f s\n", w, h, secs);
        if (!compare.empty()) {
            const lat::Image8 other = lat::read_png(compare);
            lat::require_same_size(ref, output, other, compare);
            std::printf("%s", lat::describe(lat::compare_images(ref, other)).c_str());
            if (!diff.empty()) lat::write_png(diff, lat::difference_heatmap(ref, other));
            if (explain_n > 0) explain(scene, ref, other, explain_n);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "reftrace: %s\n", e.what());
        return 1;
    }
    return 0;
}
