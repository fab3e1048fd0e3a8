// Image writers: round trips for PNG, PFM and EXR, and the failure paths (unwritable places,
// writes failing half-way), which must leave no partial or temporary file behind.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <csignal>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>

#include "input_error.h"
#include "io/image.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

using test::slurp;
using test::spit;
using test::TempDir;
using Names = std::vector<std::string>;

ImageF gradient(int w, int h) {
    ImageF img{w, h, std::vector<float>(3 * static_cast<std::size_t>(w) * h)};
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* p = &img.rgb[3 * (static_cast<std::size_t>(y) * w + x)];
            p[0] = static_cast<float>(x) / static_cast<float>(w);
            p[1] = static_cast<float>(y) * 10.5f;  // beyond 1 on purpose: floats keep it
            p[2] = -0.25f * static_cast<float>(x + y);
        }
    }
    return img;
}

// Incompressible, so files are as large as the pixel data.
Image8 noise8(int w, int h, unsigned seed = 1) {
    std::mt19937 rng(seed);
    Image8 img{w, h, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(w) * h)};
    for (auto& v : img.rgb) v = static_cast<std::uint8_t>(rng() & 0xff);
    return img;
}

ImageF noiseF(int w, int h) {
    std::mt19937 rng(2);
    ImageF img{w, h, std::vector<float>(3 * static_cast<std::size_t>(w) * h)};
    for (auto& v : img.rgb)
        v = std::bit_cast<float>(static_cast<std::uint32_t>(rng() & 0x3fffffff));
    return img;
}

using test::error_of;

TEST(ImageIo, ToByteRoundsAndClamps) {
    EXPECT_EQ(to_byte(0.0), 0);
    EXPECT_EQ(to_byte(1.0), 255);
    EXPECT_EQ(to_byte(-3.0), 0);
    EXPECT_EQ(to_byte(7.0), 255);
    EXPECT_EQ(to_byte(0.5), 128);  // 127.5 rounds up
    EXPECT_EQ(to_byte(1.0 / 255.0), 1);
    EXPECT_EQ(to_byte(0.49 / 255.0), 0);
    EXPECT_EQ(to_byte(std::numeric_limits<double>::quiet_NaN()), 0);
    EXPECT_EQ(to_byte(std::numeric_limits<double>::infinity()), 255);
    const Image8 img = to_image8(ImageF{1, 1, {0.2f, 1.5f, std::nanf("")}});
    EXPECT_EQ(img.rgb, (std::vector<std::uint8_t>{51, 255, 0}));
}

TEST(ImageIo, ToByteIsLroundOfTheScaledValue) {
    // Every half step and its neighbouring doubles, and random values: as std::lround.
    auto expected = [](double c) { return static_cast<int>(std::lround(255.0 * c)); };
    for (int k = 0; k < 255; ++k) {
        double c = (k + 0.5) / 255.0;
        for (int i = 0; i < 4; ++i) c = std::nextafter(c, 0.0);
        for (int i = 0; i < 9; ++i, c = std::nextafter(c, 1.0)) EXPECT_EQ(to_byte(c), expected(c)) << c;
    }
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 1'000'000; ++i) {
        const double c = u(rng);
        ASSERT_EQ(to_byte(c), expected(c)) << c;
    }
}

TEST(ImageIo, FormatByExtension) {
    EXPECT_EQ(image_format_for("out/a.png"), ImageFormat::png);
    EXPECT_EQ(image_format_for("A.PNG"), ImageFormat::png);
    EXPECT_EQ(image_format_for("x.Pfm"), ImageFormat::pfm);
    EXPECT_EQ(image_format_for("dir.d/x.exr"), ImageFormat::exr);
    EXPECT_EQ(error_of([] { image_format_for("x.jpg"); }),
              "x.jpg: unsupported image format '.jpg' (use .png, .pfm or .exr)");
    EXPECT_NE(error_of([] { image_format_for("dir.png/x"); }).find("dir.png/x: no image format"),
              std::string::npos);
}

TEST(ImageIo, PngRoundTripIsExact) {
    TempDir dir;
    const Image8 img = noise8(37, 23);
    write_png(dir.file("a.png"), img);
    const Image8 back = read_png(dir.file("a.png"));
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.rgb, img.rgb);
    EXPECT_EQ(dir.entries(), Names{"a.png"});
}

TEST(ImageIo, PngOverwritesExistingFile) {
    TempDir dir;
    spit(dir.file("a.png"), "old");
    write_png(dir.file("a.png"), noise8(4, 4));
    EXPECT_EQ(read_png(dir.file("a.png")).rgb, noise8(4, 4).rgb);
    EXPECT_EQ(dir.entries(), Names{"a.png"});
}

TEST(ImageIo, PfmIsLittleEndianBottomRowFirst) {
    TempDir dir;
    const ImageF img = gradient(3, 2);
    write_pfm(dir.file("a.pfm"), img);
    const std::string data = slurp(dir.file("a.pfm"));
    const std::string header = "PF\n3 2\n-1.0\n";
    ASSERT_EQ(data.substr(0, header.size()), header);
    ASSERT_EQ(data.size(), header.size() + 3 * 2 * 3 * 4);
    for (int i = 0; i < 18; ++i) {
        std::uint32_t bits = 0;
        for (int b = 0; b < 4; ++b) {
            bits |= std::uint32_t{static_cast<unsigned char>(data[header.size() + 4 * i + b])}
                    << (8 * b);
        }
        // File row 0 is the bottom row of the image (y = 1), file row 1 the top (y = 0).
        const int file_row = i / 9, x = (i % 9) / 3, c = i % 3;
        const int y = 1 - file_row;
        EXPECT_EQ(std::bit_cast<float>(bits), img.rgb[3 * (y * 3 + x) + c]) << "float " << i;
    }
    EXPECT_EQ(dir.entries(), Names{"a.pfm"});
}

TEST(ImageIo, ExrRoundTripIsExact) {
    TempDir dir;
    const ImageF img = gradient(5, 4);
    write_exr(dir.file("a.exr"), img);
    EXPECT_EQ(dir.entries(), Names{"a.exr"});

    Imf::InputFile file(dir.file("a.exr").c_str());
    const Imath::Box2i window = file.header().dataWindow();
    ASSERT_EQ(window.min.x, 0);
    ASSERT_EQ(window.min.y, 0);
    ASSERT_EQ(window.max.x, 4);
    ASSERT_EQ(window.max.y, 3);
    ImageF back{5, 4, std::vector<float>(60, -1.0f)};
    Imf::FrameBuffer frame;
    const char* names[] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        const Imf::Channel* channel = file.header().channels().findChannel(names[c]);
        ASSERT_NE(channel, nullptr) << names[c];
        EXPECT_EQ(channel->type, Imf::FLOAT);
        frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, back.rgb.data() + c, window,
                                                3 * sizeof(float), 15 * sizeof(float)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(0, 3);
    EXPECT_EQ(back.rgb, img.rgb);
}

TEST(ImageIo, WriteImageDispatchesOnExtension) {
    TempDir dir;
    const ImageF img{1, 1, {0.0f, 0.5f, 1.0f}};
    write_image(dir.file("a.PNG"), img);
    write_image(dir.file("a.pfm"), img);
    write_image(dir.file("a.exr"), img);
    EXPECT_EQ(read_png(dir.file("a.PNG")).rgb, (std::vector<std::uint8_t>{0, 128, 255}));
    EXPECT_EQ(slurp(dir.file("a.pfm")).substr(0, 2), "PF");
    EXPECT_EQ(slurp(dir.file("a.exr")).substr(0, 4), "\x76\x2f\x31\x01");
    EXPECT_NE(error_of([&] { write_image(dir.file("a.jpg"), img); }).find("unsupported"),
              std::string::npos);
    EXPECT_EQ(dir.entries(), (Names{"a.PNG", "a.exr", "a.pfm"}));
}

TEST(ImageIo, EmptyImageIsRejected) {
    TempDir dir;
    EXPECT_EQ(error_of([&] { write_png(dir.file("a.png"), Image8{}); }),
              dir.file("a.png") + ": cannot write: empty image (0x0)");
    EXPECT_NE(error_of([&] { write_exr(dir.file("a.exr"), ImageF{}); }), "");
    EXPECT_NE(error_of([&] { write_pfm(dir.file("a.pfm"), ImageF{}); }), "");
    EXPECT_TRUE(dir.entries().empty());
}

// Every way of failing to create the file, through check_writable and each writer alike.
void expect_unwritable(const std::string& path, const std::string& reason) {
    const std::string expected = path + ": cannot write: " + reason;
    EXPECT_EQ(error_of([&] { check_writable(path); }), expected);
    EXPECT_EQ(error_of([&] { write_png(path, noise8(2, 2)); }), expected);
    EXPECT_EQ(error_of([&] { write_pfm(path, gradient(2, 2)); }), expected);
    EXPECT_EQ(error_of([&] { write_exr(path, gradient(2, 2)); }), expected);
}

TEST(ImageIo, UnwritablePathsAreRejected) {
    TempDir dir;
    spit(dir.file("file"), "x");
    std::filesystem::create_directory(dir.file("sub.png"));
    expect_unwritable(dir.file("missing/a.png"), "No such file or directory");
    expect_unwritable(dir.file("file/a.png"), "Not a directory");
    expect_unwritable(dir.file("sub.png"), "Is a directory");
    expect_unwritable(dir.file("sub.png/"), "Is a directory");
    expect_unwritable("/dev/null", "not a regular file");
    EXPECT_EQ(error_of([] { check_writable(""); }), "cannot write: empty output path");
    EXPECT_EQ(dir.entries(), (Names{"file", "sub.png"}));
    EXPECT_TRUE(std::filesystem::is_empty(dir.file("sub.png")));
}

TEST(ImageIo, UnwritableDirectoryIsRejected) {
    if (::geteuid() == 0) {
        // Root ignores directory permissions, but not sysfs's: no file can be created there.
        ASSERT_TRUE(std::filesystem::is_directory("/sys"));
        expect_unwritable("/sys/lattice-test.png", "Permission denied");
        return;
    }
    TempDir dir;
    std::filesystem::create_directory(dir.file("ro"));
    std::filesystem::permissions(
        dir.file("ro"), std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    expect_unwritable(dir.file("ro/a.png"), "Permission denied");
    std::filesystem::permissions(dir.file("ro"), std::filesystem::perms::owner_all);
    EXPECT_TRUE(std::filesystem::is_empty(dir.file("ro")));
}

TEST(ImageIo, CheckWritableLeavesNothingBehind) {
    TempDir dir;
    check_writable(dir.file("a.png"));
    EXPECT_TRUE(dir.entries().empty());
    spit(dir.file("b.png"), "keep");
    check_writable(dir.file("b.png"));  // an existing file will be replaced: fine
    EXPECT_EQ(slurp(dir.file("b.png")), "keep");
    EXPECT_EQ(dir.entries(), Names{"b.png"});
}

// Makes writes beyond `bytes` fail with EFBIG ("File too large") for this process, so that a
// writer fails half-way through its temporary file.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        ::getrlimit(RLIMIT_FSIZE, &saved_);
        old_handler_ = std::signal(SIGXFSZ, SIG_IGN);  // else the process is killed
        rlimit limit = saved_;
        limit.rlim_cur = bytes;
        ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &saved_);
        std::signal(SIGXFSZ, old_handler_);
    }

private:
    rlimit saved_{};
    void (*old_handler_)(int) = nullptr;
};

TEST(ImageIo, FailedWritesKeepTheOldFileAndLeaveNoTemporary) {
    TempDir dir;
    for (const char* name : {"a.png", "a.pfm", "a.exr"}) spit(dir.file(name), "old");
    std::string png_error, pfm_error, exr_error;
    {
        FileSizeLimit limit(1000);
        png_error = error_of([&] { write_png(dir.file("a.png"), noise8(64, 64)); });
        pfm_error = error_of([&] { write_pfm(dir.file("a.pfm"), noiseF(64, 64)); });
        exr_error = error_of([&] { write_exr(dir.file("a.exr"), noiseF(64, 64)); });
    }
    const std::string reason = ": cannot write: " + std::string(std::strerror(EFBIG));
    EXPECT_EQ(png_error, dir.file("a.png") + reason);
    EXPECT_EQ(pfm_error, dir.file("a.pfm") + reason);
    EXPECT_EQ(exr_error, dir.file("a.exr") + reason);
    for (const char* name : {"a.png", "a.pfm", "a.exr"}) EXPECT_EQ(slurp(dir.file(name)), "old");
    EXPECT_EQ(dir.entries(), (Names{"a.exr", "a.pfm", "a.png"}));
}

}  // namespace
}  // namespace lat
