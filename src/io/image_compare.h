#pragma once
// Comparing two 8-bit RGB images of the same size, for `lattice compare A.png B.png [--diff D]`.
//
// Errors are per channel, in 0..255 units:
//   rmse            square root of the mean squared error over every channel of every pixel
//   psnr_db         20 log10(255 / rmse); +infinity for identical images (format_psnr: "inf")
//   mean_abs_error  mean absolute error over every channel of every pixel
//   max_abs_error   the largest absolute channel error
//   pixels_over_8   pixels whose largest channel error exceeds `threshold` (8 unless told
//                   otherwise; the names follow the default), and share_over_8 their share of
//                   all pixels, 0..1. A pixel is "off" if any channel is off by more than 8.
//   ssim            the structural similarity index, ssim() below (NaN under 11 x 11 pixels)
#include <limits>
#include <string>

#include "io/image.h"

namespace lat {

struct ImageDiffStats {
    int width = 0, height = 0;
    double rmse = 0.0;
    double psnr_db = std::numeric_limits<double>::infinity();
    double mean_abs_error = 0.0;
    int max_abs_error = 0;
    long long pixels_over_8 = 0;
    double share_over_8 = 0.0;
    int threshold = 8;
    double ssim = std::numeric_limits<double>::quiet_NaN();
};

// Throws InputError "images differ in size: a.png is 64x48, b.png is 32x32".
void require_same_size(const Image8& a, const std::string& name_a, const Image8& b,
                       const std::string& name_b);

ImageDiffStats compare_images(const Image8& a, const Image8& b, int threshold = 8);

// The structural similarity index (Wang, Bovik, Sheikh and Simoncelli 2004) in its standard
// form: an 11 x 11 Gaussian window of sigma 1.5 (weights normalised over the window),
// K1 = 0.01, K2 = 0.03, L = 255, population (not sample) covariances, the SSIM map over the
// windows that lie wholly inside the image, averaged, per RGB channel, then over the channels.
// This is scikit-image's structural_similarity(a, b, channel_axis=2, data_range=255,
// gaussian_weights=True, sigma=1.5, use_sample_covariance=False). 1 for identical images;
// images smaller than the window give NaN.
double ssim(const Image8& a, const Image8& b);

// Per pixel, the largest channel error e through the "inferno" colour map at
// t = sqrt(min(e, 64) / 64): no error is black, an error of 1 already a visible dark purple, the
// threshold 8 is magenta-red (t = 0.35), and 64 or more saturates to pale yellow.
Image8 difference_heatmap(const Image8& a, const Image8& b);

// "inf" for identical images, else two decimals: "38.92".
std::string format_psnr(double psnr_db);
// Four decimals, "0.9971"; "n/a" for images under the 11 x 11 window.
std::string format_ssim(double ssim);
// One "name: value" line per statistic, names as in ImageDiffStats.
std::string describe(const ImageDiffStats& s);

// What `lattice compare` does: reads both PNGs, compares them and, given diff_path, writes the
// heat-map there in the format its extension names (checked before anything is read). Size
// mismatches name both files.
ImageDiffStats compare_png_files(const std::string& path_a, const std::string& path_b,
                                 const std::string& diff_path = "", int threshold = 8);

}  // namespace lat
