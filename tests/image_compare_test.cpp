// compare_images against hand-computed metrics, the heat-map, and compare_png_files.
#include <gtest/gtest.h>

#include <cmath>

#include "input_error.h"
#include "io/image.h"
#include "io/image_compare.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

using test::TempDir;

Image8 filled(int w, int h, std::uint8_t v) {
    return Image8{w, h, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(w) * h, v)};
}

using test::error_of;

TEST(ImageCompare, IdenticalImagesHaveInfinitePsnr) {
    Image8 a = filled(3, 2, 40);
    a.rgb[4] = 200;
    const ImageDiffStats s = compare_images(a, a);
    EXPECT_EQ(s.width, 3);
    EXPECT_EQ(s.height, 2);
    EXPECT_TRUE(std::isinf(s.psnr_db) && s.psnr_db > 0);
    EXPECT_EQ(s.rmse, 0.0);
    EXPECT_EQ(s.mean_abs_error, 0.0);
    EXPECT_EQ(s.max_abs_error, 0);
    EXPECT_EQ(s.pixels_over_8, 0);
    EXPECT_EQ(s.share_over_8, 0.0);
    EXPECT_EQ(format_psnr(s.psnr_db), "inf");
    EXPECT_NE(describe(s).find("psnr_db: inf\n"), std::string::npos) << describe(s);
}

TEST(ImageCompare, OneChannelOfOnePixelOffByTen) {
    // 2x2 pixels = 12 channel values, one off by 10: MSE = 100 / 12, RMSE = 2.88675,
    // PSNR = 20 log10(255 / 2.88675) = 38.9226 dB; one pixel of four is off by more than 8.
    const Image8 a = filled(2, 2, 100);
    Image8 b = a;
    b.rgb[7] = 110;
    const ImageDiffStats s = compare_images(a, b);
    EXPECT_NEAR(s.rmse, 2.886751345948129, 1e-12);
    EXPECT_NEAR(s.psnr_db, 38.92261606915535, 1e-9);
    EXPECT_NEAR(s.mean_abs_error, 10.0 / 12.0, 1e-12);
    EXPECT_EQ(s.max_abs_error, 10);
    EXPECT_EQ(s.pixels_over_8, 1);
    EXPECT_EQ(s.share_over_8, 0.25);
    EXPECT_EQ(format_psnr(s.psnr_db), "38.92");
    EXPECT_EQ(describe(s),
              "size: 2x2\npsnr_db: 38.92\nrmse: 2.8868\nmean_abs_error: 0.8333\n"
              "max_abs_error: 10\npixels_over_8: 1 (25.0000%)\nssim: n/a\n");
    // Symmetric.
    EXPECT_EQ(compare_images(b, a).rmse, s.rmse);
}

TEST(ImageCompare, EveryChannelOffByOne) {
    // RMSE 1, so PSNR = 20 log10(255) = 48.1308 dB; nothing is over the threshold.
    const Image8 a = filled(4, 3, 10);
    const Image8 b = filled(4, 3, 11);
    const ImageDiffStats s = compare_images(a, b);
    EXPECT_DOUBLE_EQ(s.rmse, 1.0);
    EXPECT_NEAR(s.psnr_db, 48.1308036086791, 1e-9);
    EXPECT_EQ(s.max_abs_error, 1);
    EXPECT_EQ(s.share_over_8, 0.0);
}

TEST(ImageCompare, ThresholdIsStrictAndCountsPixelsOnce) {
    Image8 a = filled(4, 1, 0);
    Image8 b = a;
    b.rgb[0] = 8;               // pixel 0: exactly 8, not over
    b.rgb[3] = 9;               // pixel 1: 9, over
    b.rgb[6] = b.rgb[7] = 255;  // pixel 2: two channels over, counted once
    b.rgb[11] = 3;              // pixel 3: small
    ImageDiffStats s = compare_images(a, b);
    EXPECT_EQ(s.pixels_over_8, 2);
    EXPECT_EQ(s.share_over_8, 0.5);
    EXPECT_EQ(s.max_abs_error, 255);
    s = compare_images(a, b, 2);
    EXPECT_EQ(s.threshold, 2);
    EXPECT_EQ(s.pixels_over_8, 4);
    EXPECT_NE(describe(s).find("pixels_over_2: 4 (100.0000%)"), std::string::npos);
}

TEST(ImageCompare, EmptyImagesAreIdentical) {
    const ImageDiffStats s = compare_images(Image8{}, Image8{});
    EXPECT_TRUE(std::isinf(s.psnr_db));
    EXPECT_EQ(s.share_over_8, 0.0);
}

TEST(ImageCompare, SizeMismatchThrows) {
    EXPECT_EQ(error_of([] { compare_images(filled(4, 3, 0), filled(3, 4, 0)); }),
              "images differ in size: first image is 4x3, second image is 3x4");
    EXPECT_NE(error_of([] { difference_heatmap(filled(4, 3, 0), filled(4, 2, 0)); }), "");
    TempDir dir;
    write_png(dir.file("a.png"), filled(4, 3, 0));
    write_png(dir.file("b.png"), filled(2, 2, 0));
    EXPECT_EQ(error_of([&] { compare_png_files(dir.file("a.png"), dir.file("b.png")); }),
              "images differ in size: " + dir.file("a.png") + " is 4x3, " + dir.file("b.png") +
                  " is 2x2");
}

int brightness(const Image8& img, std::size_t pixel) {
    return img.rgb[3 * pixel] + img.rgb[3 * pixel + 1] + img.rgb[3 * pixel + 2];
}

TEST(ImageCompare, HeatmapIsBlackWhereEqualAndBrightensWithError) {
    const int errors[] = {0, 1, 2, 4, 8, 16, 32, 64, 200};
    const int n = static_cast<int>(std::size(errors));
    const Image8 a = filled(n, 1, 0);
    Image8 b = a;
    for (int i = 0; i < n; ++i)
        b.rgb[3 * static_cast<std::size_t>(i) + 1] = static_cast<std::uint8_t>(errors[i]);
    const Image8 heat = difference_heatmap(a, b);
    ASSERT_EQ(heat.width, n);
    ASSERT_EQ(heat.height, 1);
    EXPECT_EQ(brightness(heat, 0), 0);
    EXPECT_GT(brightness(heat, 1), 40) << "an error of 1 must be visible";
    for (std::size_t i = 2; i < 8; ++i) EXPECT_GT(brightness(heat, i), brightness(heat, i - 1));
    // Saturated from 64 on, pale yellow.
    EXPECT_EQ(std::vector<std::uint8_t>(heat.rgb.begin() + 21, heat.rgb.begin() + 24),
              std::vector<std::uint8_t>(heat.rgb.begin() + 24, heat.rgb.end()));
    EXPECT_GT(heat.rgb[21], 240);
    EXPECT_GT(heat.rgb[22], 240);
    EXPECT_LT(heat.rgb[23], 200);
}

TEST(ImageCompare, ComparePngFilesWritesTheHeatmap) {
    TempDir dir;
    const Image8 a = filled(2, 2, 100);
    Image8 b = a;
    b.rgb[7] = 110;
    write_png(dir.file("a.png"), a);
    write_png(dir.file("b.png"), b);
    const ImageDiffStats s =
        compare_png_files(dir.file("a.png"), dir.file("b.png"), dir.file("d.png"));
    EXPECT_EQ(s.pixels_over_8, 1);
    EXPECT_EQ(read_png(dir.file("d.png")).rgb, difference_heatmap(a, b).rgb);
    compare_png_files(dir.file("a.png"), dir.file("b.png"), dir.file("d.pfm"));
    EXPECT_EQ(test::slurp(dir.file("d.pfm")).substr(0, 12), "PF\n2 2\n-1.0\n");
}

TEST(ImageCompare, BadDiffPathFailsBeforeReading) {
    TempDir dir;
    // The inputs do not exist either; the diff path is reported first.
    EXPECT_EQ(error_of([&] { compare_png_files("no-a.png", "no-b.png", dir.file("x/d.png")); }),
              dir.file("x/d.png") + ": cannot write: No such file or directory");
    EXPECT_NE(error_of([&] {
                  compare_png_files("no-a.png", "no-b.png", dir.file("d.jpg"));
              }).find("unsupported image format '.jpg'"),
              std::string::npos);
    EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace lat

// SSIM: identical images give 1; flat images give the luminance term alone; a random pair
// agrees with the formula evaluated window by window.
namespace lat {
namespace {

Image8 flat_image(int w, int h, std::uint8_t v) {
    return {w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3, v)};
}

TEST(Ssim, IdenticalImagesGiveOne) {
    Image8 a = flat_image(20, 16, 0);
    for (std::size_t i = 0; i < a.rgb.size(); ++i) a.rgb[i] = static_cast<std::uint8_t>((i * 37) % 251);
    EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
}

TEST(Ssim, FlatImagesGiveTheLuminanceTerm) {
    const double c1 = 2.55 * 2.55, x = 100, y = 140;
    EXPECT_NEAR(ssim(flat_image(16, 16, 100), flat_image(16, 16, 140)),
                (2 * x * y + c1) / (x * x + y * y + c1), 1e-9);
}

TEST(Ssim, MatchesTheFormulaWindowByWindow) {
    const int w = 14, h = 12;
    Image8 a = flat_image(w, h, 0), b = flat_image(w, h, 0);
    std::uint32_t state = 12345;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        state = state * 1664525u + 1013904223u;
        a.rgb[i] = static_cast<std::uint8_t>(state >> 24);
        b.rgb[i] = static_cast<std::uint8_t>((a.rgb[i] + (state >> 16) % 40) % 256);
    }
    double g[11], gs = 0;
    for (int k = 0; k < 11; ++k) gs += g[k] = std::exp(-(k - 5) * (k - 5) / 4.5);
    const double c1 = 2.55 * 2.55, c2 = 7.65 * 7.65;
    double total = 0;
    for (int ch = 0; ch < 3; ++ch) {
        double sum = 0;
        for (int y0 = 0; y0 + 11 <= h; ++y0)
            for (int x0 = 0; x0 + 11 <= w; ++x0) {
                double mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
                for (int j = 0; j < 11; ++j)
                    for (int i = 0; i < 11; ++i) {
                        const double wt = g[i] * g[j] / (gs * gs);
                        const std::size_t p = (static_cast<std::size_t>(y0 + j) * w + x0 + i) * 3 + ch;
                        mx += wt * a.rgb[p];
                        my += wt * b.rgb[p];
                        xx += wt * a.rgb[p] * a.rgb[p];
                        yy += wt * b.rgb[p] * b.rgb[p];
                        xy += wt * a.rgb[p] * b.rgb[p];
                    }
                sum += (2 * mx * my + c1) * (2 * (xy - mx * my) + c2) /
                       ((mx * mx + my * my + c1) * (xx - mx * mx + yy - my * my + c2));
            }
        total += sum / ((w - 10) * (h - 10));
    }
    EXPECT_NEAR(ssim(a, b), total / 3, 1e-9);
    EXPECT_LT(ssim(a, b), 0.99);
    // compare (and `lattice compare`) reports it.
    const ImageDiffStats s = compare_images(a, b);
    EXPECT_EQ(s.ssim, ssim(a, b));
    EXPECT_NE(describe(s).find("\nssim: " + format_ssim(total / 3) + "\n"), std::string::npos) << describe(s);
}

}  // namespace
}  // namespace lat
