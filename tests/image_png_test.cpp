// read_png on PNGs of every colour type and bit depth, written here with libpng directly, and on
// missing, truncated, corrupt and non-PNG files.
#include <gtest/gtest.h>
#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <cstdio>

#include "io/image.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

using test::slurp;
using test::spit;
using test::TempDir;
using Bytes = std::vector<std::uint8_t>;

// A PNG described as stored: rows packed at the bit depth, 16-bit samples big-endian.
struct RawPng {
    int width = 0, height = 0;
    int color_type = PNG_COLOR_TYPE_RGB, bit_depth = 8;
    bool interlaced = false;
    std::vector<Bytes> rows;
    std::vector<png_color> palette;
    Bytes palette_alpha;  // tRNS for palette images
    double gamma = 0.0;   // writes a gAMA chunk when positive
};

[[noreturn]] void on_error(png_structp png, png_const_charp msg) {
    ADD_FAILURE() << "libpng: " << msg;
    png_longjmp(png, 1);
}

// No C++ objects live in this frame, so libpng's longjmp back to it skips no destructors.
bool encode(png_structp png, png_infop info, const RawPng& p, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, static_cast<png_uint_32>(p.width), static_cast<png_uint_32>(p.height),
                 p.bit_depth, p.color_type, p.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (!p.palette.empty()) {
        png_set_PLTE(png, info, p.palette.data(), static_cast<int>(p.palette.size()));
    }
    if (!p.palette_alpha.empty()) {
        png_set_tRNS(png, info, p.palette_alpha.data(), static_cast<int>(p.palette_alpha.size()),
                     nullptr);
    }
    if (p.gamma > 0.0) png_set_gAMA(png, info, p.gamma);
    png_write_info(png, info);
    png_write_image(png, rows);  // interlaces as needed
    png_write_end(png, nullptr);
    return true;
}

void write_raw(const std::string& path, RawPng p) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::vector<png_bytep> rows;
    for (auto& r : p.rows) rows.push_back(r.data());
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, on_error, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    const bool ok = encode(png, info, p, rows.data());
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    ASSERT_TRUE(ok);
}

RawPng raw(int width, int height, int color_type, int bit_depth, std::vector<Bytes> rows) {
    RawPng p;
    p.width = width;
    p.height = height;
    p.color_type = color_type;
    p.bit_depth = bit_depth;
    p.rows = std::move(rows);
    return p;
}

Image8 read_raw(const RawPng& p) {
    TempDir dir;
    write_raw(dir.file("a.png"), p);
    return read_png(dir.file("a.png"));
}

Bytes be16(std::initializer_list<int> values) {
    Bytes out;
    for (int v : values) {
        out.push_back(static_cast<std::uint8_t>(v >> 8));
        out.push_back(static_cast<std::uint8_t>(v & 0xff));
    }
    return out;
}

TEST(ImagePng, Gray8) {
    const Image8 img = read_raw(raw(3, 1, PNG_COLOR_TYPE_GRAY, 8, {{0, 100, 255}}));
    EXPECT_EQ(img.width, 3);
    EXPECT_EQ(img.height, 1);
    EXPECT_EQ(img.rgb, (Bytes{0, 0, 0, 100, 100, 100, 255, 255, 255}));
}

TEST(ImagePng, GrayLowBitDepthsExpandToFullRange) {
    // 1 bit: 1 0 1; 2 bits: 0 1 2 3; 4 bits: 0x0 0x7 0xf.
    EXPECT_EQ(read_raw(raw(3, 1, PNG_COLOR_TYPE_GRAY, 1, {{0b10100000}})).rgb,
              (Bytes{255, 255, 255, 0, 0, 0, 255, 255, 255}));
    EXPECT_EQ(read_raw(raw(4, 1, PNG_COLOR_TYPE_GRAY, 2, {{0b00011011}})).rgb,
              (Bytes{0, 0, 0, 85, 85, 85, 170, 170, 170, 255, 255, 255}));
    EXPECT_EQ(read_raw(raw(3, 1, PNG_COLOR_TYPE_GRAY, 4, {{0x07, 0xf0}})).rgb,
              (Bytes{0, 0, 0, 119, 119, 119, 255, 255, 255}));
}

TEST(ImagePng, SixteenBitSamplesAreScaledWithRounding) {
    // 25700 = 100 * 257 is exactly 100; 32768 is 127.502 -> 128; 0x1234 is 18.13 -> 18.
    EXPECT_EQ(
        read_raw(raw(5, 1, PNG_COLOR_TYPE_GRAY, 16, {be16({0, 65535, 25700, 32768, 0x1234})})).rgb,
        (Bytes{0, 0, 0, 255, 255, 255, 100, 100, 100, 128, 128, 128, 18, 18, 18}));
    EXPECT_EQ(read_raw(raw(1, 1, PNG_COLOR_TYPE_RGB, 16, {be16({65535, 25700, 257})})).rgb,
              (Bytes{255, 100, 1}));
}

TEST(ImagePng, AlphaIsDropped) {
    EXPECT_EQ(read_raw(raw(2, 1, PNG_COLOR_TYPE_GRAY_ALPHA, 8, {{10, 0, 200, 255}})).rgb,
              (Bytes{10, 10, 10, 200, 200, 200}));
    EXPECT_EQ(read_raw(raw(2, 1, PNG_COLOR_TYPE_RGBA, 8, {{1, 2, 3, 0, 4, 5, 6, 128}})).rgb,
              (Bytes{1, 2, 3, 4, 5, 6}));
    EXPECT_EQ(read_raw(raw(1, 1, PNG_COLOR_TYPE_RGB_ALPHA, 16, {be16({25700, 0, 65535, 0})})).rgb,
              (Bytes{100, 0, 255}));
    EXPECT_EQ(read_raw(raw(1, 1, PNG_COLOR_TYPE_GRAY_ALPHA, 16, {be16({257, 3})})).rgb,
              (Bytes{1, 1, 1}));
}

TEST(ImagePng, PaletteWithAndWithoutTransparency) {
    RawPng p = raw(3, 1, PNG_COLOR_TYPE_PALETTE, 4, {{0x21, 0x00}});
    p.palette = {{10, 20, 30}, {40, 50, 60}, {70, 80, 90}};
    EXPECT_EQ(read_raw(p).rgb, (Bytes{70, 80, 90, 40, 50, 60, 10, 20, 30}));
    p.palette_alpha = {0, 128};  // tRNS shorter than the palette, as PNG allows
    EXPECT_EQ(read_raw(p).rgb, (Bytes{70, 80, 90, 40, 50, 60, 10, 20, 30}));
    RawPng p8 = raw(2, 1, PNG_COLOR_TYPE_PALETTE, 8, {{1, 0}});
    p8.palette = {{1, 2, 3}, {4, 5, 6}};
    EXPECT_EQ(read_raw(p8).rgb, (Bytes{4, 5, 6, 1, 2, 3}));
}

TEST(ImagePng, InterlacedImage) {
    RawPng p = raw(9, 9, PNG_COLOR_TYPE_RGB, 8, {});
    p.interlaced = true;
    Bytes expected;
    for (int y = 0; y < 9; ++y) {
        Bytes row;
        for (int x = 0; x < 27; ++x) row.push_back(static_cast<std::uint8_t>(y * 27 + x));
        expected.insert(expected.end(), row.begin(), row.end());
        p.rows.push_back(row);
    }
    EXPECT_EQ(read_raw(p).rgb, expected);
}

TEST(ImagePng, GammaChunkDoesNotChangeValues) {
    RawPng p = raw(2, 1, PNG_COLOR_TYPE_RGB, 8, {{0, 64, 128, 192, 230, 255}});
    p.gamma = 1.0;
    EXPECT_EQ(read_raw(p).rgb, (Bytes{0, 64, 128, 192, 230, 255}));
}

// The message read_png throws for path, or "" if it throws none.
std::string read_error(const std::string& path) {
    try {
        read_png(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ImagePng, MissingFile) {
    TempDir dir;
    EXPECT_EQ(read_error(dir.file("none.png")),
              dir.file("none.png") + ": cannot open PNG file: No such file or directory");
    EXPECT_EQ(read_error(dir.path().string()),
              dir.path().string() + ": cannot open PNG file: it is a directory");
    EXPECT_EQ(read_error("/dev/zero"), "/dev/zero: cannot open PNG file: it is a device, not a regular file");
}

TEST(ImagePng, NotAPng) {
    TempDir dir;
    spit(dir.file("a.png"), "P6\n1 1\n255\nabc");
    EXPECT_EQ(read_error(dir.file("a.png")), dir.file("a.png") + ": not a PNG file");
    spit(dir.file("b.png"), "");
    EXPECT_EQ(read_error(dir.file("b.png")), dir.file("b.png") + ": empty file, not a PNG");
}

TEST(ImagePng, TruncatedFilesAreRejected) {
    TempDir dir;
    Image8 img{16, 16, Bytes(768)};
    for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = static_cast<std::uint8_t>(i * 7);
    write_png(dir.file("full.png"), img);
    const std::string data = slurp(dir.file("full.png"));
    // Inside the signature, after IHDR, inside IDAT, and without the final IEND chunk.
    for (std::size_t size : {std::size_t{5}, std::size_t{33}, data.size() / 2, data.size() - 12}) {
        spit(dir.file("cut.png"), data.substr(0, size));
        EXPECT_EQ(read_error(dir.file("cut.png")), dir.file("cut.png") + ": truncated PNG file")
            << "cut to " << size << " of " << data.size() << " bytes";
    }
}

TEST(ImagePng, CorruptDataIsRejected) {
    TempDir dir;
    write_png(dir.file("a.png"), Image8{4, 4, Bytes(48, 77)});
    std::string data = slurp(dir.file("a.png"));
    const std::size_t idat = data.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    data[idat + 6] = static_cast<char>(data[idat + 6] ^ 0x55);  // breaks the chunk's CRC
    spit(dir.file("a.png"), data);
    const std::string message = read_error(dir.file("a.png"));
    EXPECT_EQ(message.rfind(dir.file("a.png") + ": corrupt PNG file: ", 0), 0u) << message;
}

// A small valid PNG whose IHDR now claims width x height (with the CRC recomputed, so that
// only the size is wrong): the reproducer of the 1.2 GB allocation from a 69-byte file.
std::string png_claiming(const TempDir& dir, std::uint32_t width, std::uint32_t height) {
    write_png(dir.file("small.png"), Image8{1, 1, Bytes(3, 9)});
    std::string data = slurp(dir.file("small.png"));
    auto put32 = [&](std::size_t at, std::uint32_t v) {
        for (int b = 0; b < 4; ++b) data[at + b] = static_cast<char>(v >> (24 - 8 * b));
    };
    put32(16, width);  // IHDR data starts at 16: signature 8, length 4, type 4
    put32(20, height);
    const auto* ihdr = reinterpret_cast<const Bytef*>(data.data() + 12);
    put32(29, static_cast<std::uint32_t>(crc32(0, ihdr, 17)));  // type + 13 data bytes
    return data;
}

TEST(ImagePng, HeaderSizeIsCheckedBeforeAllocating) {
    TempDir dir;
    const std::string path = dir.file("claim.png");
    spit(path, png_claiming(dir, 20000, 20000));
    EXPECT_EQ(read_error(path),
              path + ": PNG header claims 20000 x 20000 pixels, over the limit of 268435456");
    const std::string small = png_claiming(dir, 10000, 10000);
    spit(path, small);
    EXPECT_EQ(read_error(path), path + ": PNG header claims 10000 x 10000 pixels, more than a " +
                                    std::to_string(small.size()) +
                                    "-byte file can hold (truncated or corrupt PNG file)");
    // Beyond libpng's side limit, which we set.
    spit(path, png_claiming(dir, 1u << 21, 1));
    EXPECT_EQ(read_error(path).rfind(path + ": corrupt PNG file: ", 0), 0u) << read_error(path);
}

}  // namespace
}  // namespace lat
