// The texture-mapping and particle-system modes (the paper's Table 2 baselines) against direct
// computations: a baked map of a ball on a sphere against the ball's exact shadow along the
// normals, and particle splat coverage against a capsule's exact silhouette area.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <string>

#include "render/particle_mode.h"
#include "render/render_modes.h"
#include "render/texture_mode.h"
#include "scene/scene_loader.h"
#include "util/error.h"

namespace lat {
namespace {

// A hair of one cylinder (length 6, radius 0.5) seen side-on from far away, lit only by
// ambient light in white: each pixel's value is the share of it the hair covers.
std::string capsule_scene(int width) {
    return R"({"camera": {"eye": [0, -400, 3], "look_at": [0, 0, 3], "up": [0, 0, 1], "fov_y_deg": 2,
       "width": )" + std::to_string(width) + R"(, "height": )" + std::to_string(width) + R"(},
       "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": false, "lights": [],
       "materials": {"white": {"color": [1, 1, 1], "ka": 1, "kd": 0, "ks": 0}},
       "primitives": {"hair": {"spheres": [[0, 0, 0, 0.5], [0, 0, 6, 0.5]], "cylinders": [[0, 1, 0.5]]}},
       "objects": [{"type": "instance", "primitive": "hair", "material": "white",
                    "transform": [{"rotate": {"axis": [0, 1, 0], "angle_deg": 30}}]}]})";
}

double covered_pixels(const RenderOutput& out) {
    double sum = 0;
    for (std::size_t i = 0; i < out.radiance.rgb.size(); i += 3) sum += static_cast<double>(out.radiance.rgb[i]);
    return sum;
}

TEST(ParticleMode, SplatCoverageMatchesTheExactSilhouetteArea) {
    const Scene s = load_scene_text(capsule_scene(96), "capsule.json");
    const ParticleSet set = make_particles(s);
    ASSERT_EQ(set.particles.size(), 6u);  // 6 long, radius 0.5: pieces of length 1
    ParticleOptions opt;
    opt.spp = 16;
    const double particles = covered_pixels(render_particles(s, set, opt));
    // The capsule's silhouette side-on: a 6 x 1 rectangle and a disc of radius 0.5, at 400
    // units through a 2 degree field of 96 pixels.
    const double px_per_unit = 96 / (2 * 400 * std::tan(M_PI / 180));
    const double exact = (6 * 1 + M_PI * 0.25) * px_per_unit * px_per_unit;
    EXPECT_NEAR(particles / exact, 1.0, 0.03) << particles << " vs " << exact;
    // And the ray-traced silhouette agrees with both.
    ModeSettings ms;
    ms.spp = 16;
    const double traced = covered_pixels(render_in_mode(s, RenderMode::kExact, ms).out);
    EXPECT_NEAR(traced / exact, 1.0, 0.03);
}

TEST(ParticleMode, ImagesAreIdenticalForAnyThreadCount) {
    const Scene s = load_scene_text(capsule_scene(48), "capsule.json");
    ModeSettings ms;
    ms.spp = 4;
    RenderOutput one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = render_in_mode(s, RenderMode::kParticles, ms).out;
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = render_in_mode(s, RenderMode::kParticles, ms).out;
    }
    EXPECT_EQ(one.display.rgb, two.display.rgb);
}

// A ball of radius 0.3 centred 1.15 from the centre of a unit sphere, rooted on its top; a
// second sphere far off, which must not be taken for the base.
const char* kBallScene = R"({
  "camera": {"eye": [0, -6, 3], "look_at": [0, 0, 0.5], "fov_y_deg": 30, "width": 48, "height": 48},
  "lights": [{"position": [4, -5, 6]}],
  "materials": {"skin": {"color": [0.8, 0.5, 0.3]}, "fur": {"color": [0.2, 0.4, 0.6]}},
  "primitives": {"ball": {"spheres": [[0, 0, 0, 0.3]], "cylinders": []}},
  "objects": [{"type": "sphere", "center": [10, 0, 0], "radius": 1, "material": "skin"},
              {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "skin"},
              {"type": "instance", "primitive": "ball", "material": "fur",
               "transform": [{"translate": [0, 0, 1.15]}]}]})";

TEST(TextureMode, BakedBallMatchesItsExactProjection) {
    const Scene s = load_scene_text(kBallScene, "ball.json");
    TextureOptions opt;
    opt.width = 256;
    opt.subsamples = 4;
    const TextureMaps maps = bake_texture(s, opt);
    EXPECT_EQ(maps.base_object, 1u);
    ASSERT_EQ(maps.width, 256);
    ASSERT_EQ(maps.height, 128);
    // Solid angle covered: radial lines meet the ball when 1.15 sin(theta) <= 0.3.
    const double theta0 = std::asin(0.3 / 1.15);
    const double exact = 2 * M_PI * (1 - std::cos(theta0));
    double baked = 0;
    for (int j = 0; j < maps.height; ++j) {
        const double omega = (2 * M_PI / maps.width) *
                              (std::cos(M_PI * j / maps.height) - std::cos(M_PI * (j + 1) / maps.height));
        for (int i = 0; i < maps.width; ++i) {
            const std::size_t t = static_cast<std::size_t>(j) * maps.width + i;
            baked += omega * maps.colour_coverage[4 * t + 3] / 255.0;
            if (maps.colour_coverage[4 * t + 3] == 255) {  // fully covered: the fur's colour
                EXPECT_NEAR(maps.colour_coverage[4 * t] / 255.0, 0.2, 1 / 255.0);
                EXPECT_NEAR(maps.colour_coverage[4 * t + 2] / 255.0, 0.6, 1 / 255.0);
            }
        }
    }
    EXPECT_NEAR(baked / exact, 1.0, 0.02);
    // The normal where the line at theta = theta0 / 2 leaves the ball's upper side.
    const double theta = theta0 / 2;
    const Vec3 d{std::sin(theta), 0, std::cos(theta)}, c{0, 0, 1.15};
    const double b = dot(d, c), far = b + std::sqrt(b * b - (dot(c, c) - 0.09));
    const Vec3 n = (d * far - c) / 0.3;
    const TextureMaps::Sample sample = maps.lookup(d);
    EXPECT_GT(dot(sample.normal, n), std::cos(3 * M_PI / 180));
    EXPECT_NEAR(sample.coverage, 1.0, 1e-9);
    EXPECT_NEAR(maps.lookup({0, 0, -1}).coverage, 0.0, 1e-9);
}

TEST(TextureMode, NeedsASphereToMapOnto) {
    const Scene s = load_scene_text(capsule_scene(8), "capsule.json");
    try {
        bake_texture(s, {});
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("capsule.json: objects[0]: texture mode"), std::string::npos)
            << e.what();
    }
}

TEST(TextureMode, ImagesAreIdenticalForAnyThreadCount) {
    const Scene s = load_scene_text(kBallScene, "ball.json");
    ModeSettings ms;
    ms.spp = 4;
    ms.texture.width = 64;
    RenderOutput one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = render_in_mode(s, RenderMode::kTexture, ms).out;
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = render_in_mode(s, RenderMode::kTexture, ms).out;
    }
    EXPECT_EQ(one.display.rgb, two.display.rgb);
}

}  // namespace
}  // namespace lat
