#include "io/image_compare.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "util/error.h"

namespace lat {

namespace {

std::string size_text(const Image8& img) {
    return std::to_string(img.width) + "x" + std::to_string(img.height);
}

// Largest channel error of pixel i.
int pixel_error(const Image8& a, const Image8& b, std::size_t i) {
    int e = 0;
    for (std::size_t c = 3 * i; c < 3 * i + 3; ++c) e = std::max(e, std::abs(a.rgb[c] - b.rgb[c]));
    return e;
}

// Matplotlib's "inferno" as degree-6 polynomials per channel, fitted by Matt Zucker
// (shadertoy.com/view/WlfXRN, CC0); within about 1/255 of the table.
std::array<std::uint8_t, 3> inferno(double t) {
    static constexpr double k[3][7] = {
        {0.0002189403691192265, 0.1065134194856116, 11.60249308247187, -41.70399613139459,
         77.162935699427, -71.31942824499214, 25.13112622477341},
        {0.001651004631001012, 0.5639564367884091, -3.972853965665698, 17.43639888205313,
         -33.40235894210092, 32.62606426397723, -12.24266895238567},
        {-0.01948089843709184, 3.932712388889277, -15.9423941062914, 44.35414519872813,
         -81.80730925738993, 73.20951985803202, -23.07032500287172},
    };
    std::array<std::uint8_t, 3> rgb{};
    for (int c = 0; c < 3; ++c) {
        double v = 0.0;
        for (int i = 6; i >= 0; --i) v = v * t + k[c][i];
        rgb[c] = to_byte(v);
    }
    return rgb;
}

// The heat-map is 8-bit; PFM and EXR get it as floats c / 255, which to_byte maps back exactly.
void write_heatmap(const std::string& path, const Image8& img) {
    if (image_format_for(path) == ImageFormat::png) return write_png(path, img);
    ImageF f{img.width, img.height, std::vector<float>(img.rgb.size())};
    std::transform(img.rgb.begin(), img.rgb.end(), f.rgb.begin(),
                   [](std::uint8_t c) { return static_cast<float>(c) / 255.0f; });
    write_image(path, f);
}

}  // namespace

void require_same_size(const Image8& a, const std::string& name_a, const Image8& b,
                       const std::string& name_b) {
    if (a.width == b.width && a.height == b.height) return;
    throw InputError("images differ in size: " + name_a + " is " + size_text(a) + ", " + name_b +
                     " is " + size_text(b));
}

ImageDiffStats compare_images(const Image8& a, const Image8& b, int threshold) {
    require_same_size(a, "first image", b, "second image");
    const std::size_t pixels =
        static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
    assert(a.rgb.size() == 3 * pixels && b.rgb.size() == 3 * pixels);
    assert(threshold >= 0);

    ImageDiffStats s;
    s.width = a.width;
    s.height = a.height;
    s.threshold = threshold;
    std::uint64_t sum_abs = 0, sum_sq = 0;
    for (std::size_t c = 0; c < 3 * pixels; ++c) {
        const auto e = static_cast<std::uint64_t>(std::abs(a.rgb[c] - b.rgb[c]));
        sum_abs += e;
        sum_sq += e * e;
    }
    for (std::size_t i = 0; i < pixels; ++i) {
        const int e = pixel_error(a, b, i);
        s.max_abs_error = std::max(s.max_abs_error, e);
        if (e > threshold) ++s.pixels_over_8;
    }
    s.ssim = ssim(a, b);
    if (pixels == 0) return s;  // nothing differs: the defaults (zeros, infinite PSNR) hold
    const auto channels = static_cast<double>(3 * pixels);
    s.mean_abs_error = static_cast<double>(sum_abs) / channels;
    s.rmse = std::sqrt(static_cast<double>(sum_sq) / channels);
    if (sum_sq != 0) s.psnr_db = 20.0 * std::log10(255.0 / s.rmse);
    s.share_over_8 = static_cast<double>(s.pixels_over_8) / static_cast<double>(pixels);
    return s;
}

double ssim(const Image8& a, const Image8& b) {
    require_same_size(a, "first image", b, "second image");
    constexpr int kWin = 11, kHalf = kWin / 2;
    const int w = a.width, h = a.height;
    if (w < kWin || h < kWin) return std::numeric_limits<double>::quiet_NaN();
    std::array<double, kWin> g{};
    double gsum = 0;
    for (int k = 0; k < kWin; ++k) gsum += g[k] = std::exp(-(k - kHalf) * (k - kHalf) / (2 * 1.5 * 1.5));
    for (double& x : g) x /= gsum;
    const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    // The five moments, filtered along rows ("valid" columns only), then along columns.
    const int vw = w - kWin + 1, vh = h - kWin + 1;
    double total = 0;
    std::vector<double> rows(static_cast<std::size_t>(h) * vw * 5);
    for (int ch = 0; ch < 3; ++ch) {
        auto at = [&](const Image8& im, int x, int y) {
            return static_cast<double>(im.rgb[(static_cast<std::size_t>(y) * w + x) * 3 + ch]);
        };
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < vw; ++x) {
                double m[5] = {0, 0, 0, 0, 0};
                for (int k = 0; k < kWin; ++k) {
                    const double p = at(a, x + k, y), q = at(b, x + k, y);
                    m[0] += g[k] * p;
                    m[1] += g[k] * q;
                    m[2] += g[k] * p * p;
                    m[3] += g[k] * q * q;
                    m[4] += g[k] * p * q;
                }
                std::copy(m, m + 5, rows.begin() + (static_cast<std::ptrdiff_t>(y) * vw + x) * 5);
            }
        double sum = 0;
        for (int y = 0; y < vh; ++y)
            for (int x = 0; x < vw; ++x) {
                double m[5] = {0, 0, 0, 0, 0};
                for (int k = 0; k < kWin; ++k)
                    for (int i = 0; i < 5; ++i)
                        m[i] += g[k] * rows[(static_cast<std::size_t>(y + k) * vw + x) * 5 + i];
                const double vx = m[2] - m[0] * m[0], vy = m[3] - m[1] * m[1], cxy = m[4] - m[0] * m[1];
                sum += (2 * m[0] * m[1] + c1) * (2 * cxy + c2) /
                       ((m[0] * m[0] + m[1] * m[1] + c1) * (vx + vy + c2));
            }
        total += sum / (static_cast<double>(vw) * vh);
    }
    return total / 3;
}

Image8 difference_heatmap(const Image8& a, const Image8& b) {
    require_same_size(a, "first image", b, "second image");
    const std::size_t pixels =
        static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
    // One colour per possible error, computed once.
    std::array<std::array<std::uint8_t, 3>, 256> colours{};
    for (int e = 1; e < 256; ++e) colours[e] = inferno(std::sqrt(std::min(e, 64) / 64.0));
    Image8 out{a.width, a.height, std::vector<std::uint8_t>(3 * pixels)};
    for (std::size_t i = 0; i < pixels; ++i) {
        const auto& colour = colours[static_cast<std::size_t>(pixel_error(a, b, i))];
        std::copy(colour.begin(), colour.end(),
                  out.rgb.begin() + static_cast<std::ptrdiff_t>(3 * i));
    }
    return out;
}

std::string format_psnr(double psnr_db) {
    if (std::isinf(psnr_db)) return psnr_db > 0 ? "inf" : "-inf";
    char text[32];
    std::snprintf(text, sizeof text, "%.2f", psnr_db);
    return text;
}

std::string format_ssim(double ssim) {
    if (std::isnan(ssim)) return "n/a";
    char text[32];
    std::snprintf(text, sizeof text, "%.4f", ssim);
    return text;
}

std::string describe(const ImageDiffStats& s) {
    char share[32], rmse[32], mean[32];
    std::snprintf(share, sizeof share, "%.4f%%", 100.0 * s.share_over_8);
    std::snprintf(rmse, sizeof rmse, "%.4f", s.rmse);
    std::snprintf(mean, sizeof mean, "%.4f", s.mean_abs_error);
    return "size: " + std::to_string(s.width) + "x" + std::to_string(s.height) +
           "\npsnr_db: " + format_psnr(s.psnr_db) + "\nrmse: " + rmse +
           "\nmean_abs_error: " + mean + "\nmax_abs_error: " + std::to_string(s.max_abs_error) +
           "\npixels_over_" + std::to_string(s.threshold) + ": " + std::to_string(s.pixels_over_8) +
           " (" + share + ")\nssim: " + format_ssim(s.ssim) + "\n";
}

ImageDiffStats compare_png_files(const std::string& path_a, const std::string& path_b,
                                 const std::string& diff_path, int threshold) {
    if (!diff_path.empty()) {
        image_format_for(diff_path);
        check_writable(diff_path);
    }
    const Image8 a = read_png(path_a);
    const Image8 b = read_png(path_b);
    require_same_size(a, path_a, b, path_b);
    const ImageDiffStats stats = compare_images(a, b, threshold);
    if (!diff_path.empty()) write_heatmap(diff_path, difference_heatmap(a, b));
    return stats;
}

}  // namespace lat
