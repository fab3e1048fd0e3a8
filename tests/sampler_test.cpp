// The samplers of render/core/sampler.h: where their offsets fall (in the pixel, on the grid, in the
// elementary intervals), that images are the same bytes on any thread count, and that a few
// samples of each come close to a many-sample truth.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include "io/image_compare.h"
#include "render/core/camera.h"
#include "render/modes/integrators.h"
#include "render/core/shading.h"
#include "render/core/sampler.h"
#include "scene/scene_loader.h"
#include "test_paths.h"

namespace lat {
namespace {

std::vector<SamplerKind> all_samplers() {
    std::vector<SamplerKind> v;
    for (const SamplerDescription& d : samplers()) v.push_back(d.kind);
    return v;
}

TEST(Sampler, NamesAreDistinctAndTheDefaultIsOne) {
    std::set<std::string_view> names;
    for (const SamplerDescription& d : samplers()) names.insert(d.name);
    EXPECT_EQ(names.size(), samplers().size());
    EXPECT_EQ(sampler_description(kDefaultSampler).kind, kDefaultSampler);
}

TEST(Sampler, OffsetsLieInThePixel) {
    for (const SamplerKind kind : all_samplers())
        for (const int spp : {1, 2, 3, 4, 7, 9, 16, 64, 256}) {
            const PixelSampler s(kind, spp);
            ASSERT_EQ(s.spp(), spp);
            for (std::uint64_t pixel : {0ull, 1ull, 511ull, 262143ull, 4294967295ull})
                for (int k = 0; k < spp; ++k) {
                    const auto [x, y] = s.offset(pixel, k);
                    ASSERT_TRUE(x >= 0 && x < 1 && y >= 0 && y < 1)
                        << sampler_description(kind).name << " spp " << spp << " k " << k;
                }
        }
}

TEST(Sampler, OneSampleIsThePixelCentre) {
    for (const SamplerKind kind : all_samplers()) {
        const auto [x, y] = PixelSampler(kind, 1).offset(12345, 0);
        EXPECT_EQ(x, 0.5);
        EXPECT_EQ(y, 0.5);
    }
}

TEST(Sampler, TheGridTakesCellCentres) {
    const PixelSampler four(SamplerKind::kGrid, 4);
    const std::vector<std::array<double, 2>> want{{0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}, {0.75, 0.75}};
    for (int k = 0; k < 4; ++k) EXPECT_EQ(four.offset(99, k), want[static_cast<std::size_t>(k)]);
    const PixelSampler six(SamplerKind::kGrid, 6);  // 2 x 3
    EXPECT_EQ(six.offset(7, 5), (std::array<double, 2>{0.75, 5.0 / 6}));
}

// Sample k's cell in the nx x ny grid of the pixel.
std::pair<int, int> cell(std::array<double, 2> o, int nx, int ny) {
    return {static_cast<int>(o[0] * nx), static_cast<int>(o[1] * ny)};
}

TEST(Sampler, JitterPutsOneSampleInEachCellOfItsGrid) {
    for (const int spp : {2, 4, 6, 9, 16}) {
        int nx, ny;
        stratify(spp, nx, ny);
        const PixelSampler s(SamplerKind::kJitter, spp);
        for (std::uint64_t pixel = 0; pixel < 50; ++pixel)
            for (int k = 0; k < spp; ++k)
                EXPECT_EQ(cell(s.offset(pixel, k), nx, ny), std::make_pair(k % nx, k / nx));
    }
}

// The jitter's offsets are those images were always rendered with (splitmix64 of the pixel and
// sample): a change here would change every image at the same settings.
TEST(Sampler, JitterKeepsItsOffsets) {
    const PixelSampler s(SamplerKind::kJitter, 4);
    EXPECT_EQ(s.offset(0, 0), (std::array<double, 2>{0x1.c4415072f63b9p-2, 0x1.4e0dba5e9a32fp-2}));
    EXPECT_EQ(s.offset(1000, 3), (std::array<double, 2>{0x1.85f6b5b20fb62p-1, 0x1.5d440286cd09p-1}));
}

// Whether every elementary interval of area 1/n (2^a x 2^b cells, a + b = log2 n) holds exactly
// one of the points: the (0,m,2)-net property.
bool is_net(const std::vector<std::array<double, 2>>& points) {
    const int n = static_cast<int>(points.size());
    int m = 0;
    while ((1 << m) < n) ++m;
    if ((1 << m) != n) return false;
    for (int a = 0; a <= m; ++a) {
        const int nx = 1 << a, ny = 1 << (m - a);
        std::set<std::pair<int, int>> cells;
        for (const auto& p : points) cells.insert(cell(p, nx, ny));
        if (static_cast<int>(cells.size()) != n) return false;
    }
    return true;
}

std::vector<std::array<double, 2>> pixel_samples(SamplerKind kind, int spp, std::uint64_t pixel) {
    const PixelSampler s(kind, spp);
    std::vector<std::array<double, 2>> v;
    for (int k = 0; k < spp; ++k) v.push_back(s.offset(pixel, k));
    return v;
}

TEST(Sampler, SobolIsANetInEveryPixel) {
    for (const int spp : {2, 4, 16, 64})
        for (std::uint64_t pixel = 0; pixel < 200; ++pixel)
            ASSERT_TRUE(is_net(pixel_samples(SamplerKind::kSobol, spp, pixel)))
                << "spp " << spp << " pixel " << pixel;
    // A power-of-two prefix of the sequence is a net too: the first 4 of 16.
    auto first4 = pixel_samples(SamplerKind::kSobol, 16, 5);
    first4.resize(4);
    EXPECT_TRUE(is_net(first4));
}

TEST(Sampler, TheNetTestTellsStratificationFromANet) {
    // Jitter has one sample per cell of its 2 x 2 (4 x 4) grid but not per column of 4 (16):
    // in most pixels two share a column.
    int nets = 0;
    for (std::uint64_t pixel = 0; pixel < 100; ++pixel) nets += is_net(pixel_samples(SamplerKind::kJitter, 16, pixel));
    EXPECT_LT(nets, 5);
}

TEST(Sampler, PixelsAreScrambledApart) {
    for (const SamplerKind kind : {SamplerKind::kJitter, SamplerKind::kSobol}) {
        std::set<std::array<double, 2>> first;
        for (std::uint64_t pixel = 0; pixel < 100; ++pixel) first.insert(PixelSampler(kind, 4).offset(pixel, 0));
        EXPECT_EQ(first.size(), 100u) << sampler_description(kind).name;
    }
}

// Plate 4 (a ball of 1000 hairs over a floor) shrunk to a few pixels, where the hairs are finer
// than a pixel.
Scene small_plate4(int size) {
    Scene s = load_scene(test::source_path("examples/plate4-fuzzy-sphere-1000.json"));
    s.camera.width = s.camera.height = size;
    return s;
}

TEST(Sampler, ImagesAreTheSameOnOneAndTwoThreads) {
    const Scene s = small_plate4(24);
    const TracedScene rs(s);
    for (const SamplerKind kind : all_samplers()) {
        RenderOptions opt;
        opt.spp = 4;
        opt.sampler = kind;
        RenderOutput one, two;
        {
            tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
            one = render_exact(rs, opt);
        }
        {
            tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
            two = render_exact(rs, opt);
        }
        EXPECT_EQ(one.radiance.rgb, two.radiance.rgb) << sampler_description(kind).name;
        EXPECT_EQ(one.display.rgb, two.display.rgb) << sampler_description(kind).name;
        EXPECT_EQ(one.stats.sampler, sampler_description(kind).name);
    }
}

// The pixels' mean of n x n samples at the cells' centres, traced here rather than through
// render_image and its samplers, so that a broken sampler cannot break its own truth.
Image8 truth_image(const TracedScene& rs, int n) {
    const Scene& s = rs.scene();
    const PinholeCamera cam(s.camera);
    Image8 im{s.camera.width, s.camera.height,
              std::vector<std::uint8_t>(static_cast<std::size_t>(s.camera.width) * s.camera.height * 3)};
    ShadeState state;
    for (int j = 0; j < s.camera.height; ++j)
        for (int i = 0; i < s.camera.width; ++i) {
            Vec3 sum;
            for (int k = 0; k < n * n; ++k) {
                const Ray ray = cam.ray(i, j, (k % n + 0.5) / n, (k / n + 0.5) / n);
                SurfaceHit hit;
                const Vec3 c = rs.intersect(ray, 0.0, kInfinity, hit) ? shade(rs, ray, hit, state) : s.background;
                sum += Vec3{std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0), std::clamp(c.z, 0.0, 1.0)};
            }
            for (int ch = 0; ch < 3; ++ch)
                im.rgb[(static_cast<std::size_t>(j) * s.camera.width + i) * 3 + ch] = to_byte(sum[ch] / (n * n));
        }
    return im;
}

// Each sampler at 4 spp comes within the tolerance of a 256-sample truth; the pixel centre
// alone (an aliased image, as is one with every sample at the same point) does not.
TEST(Sampler, FourSamplesComeCloseToTheTruth) {
    const Scene s = small_plate4(40);
    const TracedScene rs(s);
    const Image8 truth = truth_image(rs, 16);
    constexpr double kMinPsnr = 26.0;  // the samplers 28.9-29.8 dB, the centre 22.5
    RenderOptions opt;
    const RenderOutput centre = render_exact(rs, opt);
    EXPECT_EQ(centre.stats.sampler, "centre");
    EXPECT_LT(compare_images(centre.display, truth).psnr_db, kMinPsnr);
    for (const SamplerKind kind : all_samplers()) {
        opt.spp = 4;
        opt.sampler = kind;
        EXPECT_GT(compare_images(render_exact(rs, opt).display, truth).psnr_db, kMinPsnr)
            << sampler_description(kind).name;
    }
}

}  // namespace
}  // namespace lat
