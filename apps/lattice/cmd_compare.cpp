// lattice compare A.png B.png [--diff D.png] [--threshold N] [--json]
// PSNR, RMSE, errors, share of pixels off and SSIM (io/image_compare.h says how each is defined).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "io/image_compare.h"

namespace lat::cli {
namespace {

struct CompareArgs {
    std::string a, b, diff;
    int threshold = 8;
    bool json = false;
};

int run_compare(const CompareArgs& args) {
    const ImageDiffStats s = compare_png_files(args.a, args.b, args.diff, args.threshold);
    if (args.json) {
        nlohmann::json j = {{"a", args.a},
                            {"b", args.b},
                            {"width", s.width},
                            {"height", s.height},
                            {"psnr_db", std::isinf(s.psnr_db) ? nlohmann::json("inf") : nlohmann::json(s.psnr_db)},
                            {"rmse", s.rmse},
                            {"mean_abs_error", s.mean_abs_error},
                            {"max_abs_error", s.max_abs_error},
                            {"threshold", s.threshold},
                            {"pixels_over_threshold", s.pixels_over_8},
                            {"share_over_threshold", s.share_over_8},
                            {"ssim", std::isnan(s.ssim) ? nlohmann::json(nullptr) : nlohmann::json(s.ssim)}};
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("%s", describe(s).c_str());
    }
    return 0;
}

}  // namespace

Command add_compare_command(CLI::App& parent) {
    auto args = std::make_shared<CompareArgs>();
    Command c;
    c.app = parent.add_subcommand(
        "compare", "Compare two PNG images: PSNR, RMSE, largest error, share of pixels off, SSIM");
    c.app->add_option("a", args->a, "First image (PNG)")->required();
    c.app->add_option("b", args->b, "Second image (PNG)")->required();
    c.app->add_option("--diff", args->diff, "Write a heat-map of the difference (.png, .pfm, .exr)");
    c.app->add_option("--threshold", args->threshold,
                      "A pixel is off when a channel differs by more than this (0..255)")
        ->check(CLI::Range(0, 255));
    c.app->add_flag("--json", args->json, "Machine-readable output");
    c.run = [args] { return run_compare(*args); };
    return c;
}

}  // namespace lat::cli
