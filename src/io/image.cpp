#include "io/image.h"

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>

#include "util/atomic_file.h"
#include "util/error.h"

namespace lat {

std::uint8_t to_byte(double c) {
    if (!(c > 0.0)) return 0;  // also catches NaN
    if (c >= 1.0) return 255;
    // std::lround(v) (halves away from zero) without libm's call, three a pixel: v - floor(v)
    // is exact for 0 < v < 255.
    const double v = 255.0 * c;
    const auto whole = static_cast<int>(v);
    return static_cast<std::uint8_t>(v - whole >= 0.5 ? whole + 1 : whole);
}

Image8 to_image8(const ImageF& img) {
    assert(img.rgb.size() == 3 * static_cast<std::size_t>(img.width) * img.height);
    Image8 out{img.width, img.height, std::vector<std::uint8_t>(img.rgb.size())};
    std::transform(img.rgb.begin(), img.rgb.end(), out.rgb.begin(),
                   [](float c) { return to_byte(static_cast<double>(c)); });
    return out;
}

ImageFormat image_format_for(const std::string& path) {
    const std::string ext = std::filesystem::path(path).extension().string();
    std::string lower = ext;
    for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (lower == ".png") return ImageFormat::png;
    if (lower == ".pfm") return ImageFormat::pfm;
    if (lower == ".exr") return ImageFormat::exr;
    const std::string what =
        ext.empty() ? "no image format extension" : "unsupported image format '" + ext + "'";
    throw InputError(located_message(path, "", what + " (use .png, .pfm or .exr)"));
}

void require_nonempty_image(const std::string& path, int width, int height) {
    if (width <= 0 || height <= 0) {
        throw_write_error(
            path, "empty image (" + std::to_string(width) + "x" + std::to_string(height) + ")");
    }
}

void check_writable(const std::string& path) {
    // The writers' own temporary: its constructor does every check, its destructor removes it.
    const AtomicFile probe(path);
}

void write_image(const std::string& path, const ImageF& img) {
    switch (image_format_for(path)) {
        case ImageFormat::png:
            return write_png(path, to_image8(img));
        case ImageFormat::pfm:
            return write_pfm(path, img);
        case ImageFormat::exr:
            return write_exr(path, img);
    }
}

void write_pfm(const std::string& path, const ImageF& img) {
    require_nonempty_image(path, img.width, img.height);
    assert(img.rgb.size() == 3 * static_cast<std::size_t>(img.width) * img.height);
    AtomicFile out(path);
    // A negative scale means little-endian floats; PFM stores the bottom row first.
    const std::string header =
        "PF\n" + std::to_string(img.width) + " " + std::to_string(img.height) + "\n-1.0\n";
    out.write(header.data(), header.size());
    const std::size_t floats_per_row = 3 * static_cast<std::size_t>(img.width);
    std::vector<unsigned char> row(4 * floats_per_row);
    for (int y = img.height - 1; y >= 0; --y) {
        const float* src = img.rgb.data() + static_cast<std::size_t>(y) * floats_per_row;
        for (std::size_t i = 0; i < floats_per_row; ++i) {
            const auto bits = std::bit_cast<std::uint32_t>(src[i]);
            for (int b = 0; b < 4; ++b)
                row[4 * i + b] = static_cast<unsigned char>(bits >> (8 * b));
        }
        out.write(row.data(), row.size());
    }
    out.commit();
}

namespace {

// OpenEXR output over our temporary's FILE*. It remembers the first OS error, because
// ~OutputFile writes the line offset table and swallows any exception doing so.
class FileOStream : public Imf::OStream {
  public:
    FileOStream(std::FILE* f, const std::string& name) : Imf::OStream(name.c_str()), file_(f) {}

    void write(const char c[], int n) override {
        if (n > 0 &&
            std::fwrite(c, 1, static_cast<std::size_t>(n), file_) != static_cast<std::size_t>(n)) {
            fail();
        }
    }
    std::uint64_t tellp() override {
        const off_t pos = ::ftello(file_);
        if (pos < 0) fail();
        return static_cast<std::uint64_t>(pos);
    }
    void seekp(std::uint64_t pos) override {
        if (::fseeko(file_, static_cast<off_t>(pos), SEEK_SET) != 0) fail();
    }
    int error() const { return error_; }

  private:
    [[noreturn]] void fail() {
        if (error_ == 0) error_ = errno != 0 ? errno : EIO;
        throw Iex::IoExc(std::strerror(error_));
    }

    std::FILE* file_;
    int error_ = 0;
};

}  // namespace

void write_exr(const std::string& path, const ImageF& img) {
    require_nonempty_image(path, img.width, img.height);
    assert(img.rgb.size() == 3 * static_cast<std::size_t>(img.width) * img.height);
    AtomicFile out(path);
    FileOStream stream(out.file(), path);
    try {
        Imf::Header header(img.width, img.height);
        const Imath::Box2i window = header.dataWindow();
        const std::size_t x_stride = 3 * sizeof(float);
        const std::size_t y_stride = x_stride * static_cast<std::size_t>(img.width);
        Imf::FrameBuffer frame;
        const char* names[] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c) {
            header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
            frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, img.rgb.data() + c, window,
                                                    x_stride, y_stride));
        }
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(img.height);
    } catch (const std::exception& e) {
        if (stream.error() != 0) throw_write_errno(path, stream.error());
        throw_write_error(path, e.what());
    }
    if (stream.error() != 0) throw_write_errno(path, stream.error());
    out.commit();
}

}  // namespace lat
