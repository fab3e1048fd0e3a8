#pragma once
// Images in memory and on disk. Rendering produces linear float RGB; the 8-bit form is
// round(255 * clamp(c, 0, 1)) with no gamma, as the reference rule says.
#include <cstdint>
#include <string>
#include <vector>

namespace lat {

struct ImageF {
    int width = 0, height = 0;
    std::vector<float> rgb;  // row-major, row 0 at the top, 3 floats per pixel
};

struct Image8 {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  // row-major, row 0 at the top, 3 bytes per pixel
};

std::uint8_t to_byte(double c);  // round(255 * clamp(c, 0, 1)); NaN gives 0
Image8 to_image8(const ImageF& img);

// Writers go through a temporary file in the same directory and rename it into place
// (util/atomic_file.h), so a failed or interrupted write never leaves a partial image. Errors throw
// lat::InputError naming the path.
void write_png(const std::string& path, const Image8& img);
void write_pfm(const std::string& path, const ImageF& img);
void write_exr(const std::string& path, const ImageF& img);
// Writes in the format image_format_for(path) names; PNG goes through to_image8.
void write_image(const std::string& path, const ImageF& img);

// Any PNG colour type / bit depth, as 8-bit RGB. Samples are taken as stored (no gamma or colour
// management), 16-bit ones scaled with rounding; alpha and tRNS transparency are dropped, not
// composited. Missing, truncated or corrupt files throw InputError naming the path.
Image8 read_png(const std::string& path);

enum class ImageFormat { png, pfm, exr };
// By extension (case-insensitive): .png, .pfm, .exr; throws InputError for anything else.
ImageFormat image_format_for(const std::string& path);
// Image files cannot hold an empty image; throws InputError naming the path for one.
void require_nonempty_image(const std::string& path, int width, int height);
// Throws InputError if the file cannot be created there (missing directory, no permission,
// a directory in the way), without leaving anything behind. It creates and removes the same
// temporary file the writers would use, so it checks exactly what they need.
void check_writable(const std::string& path);

}  // namespace lat
