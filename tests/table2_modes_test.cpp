// The texture-mapping and particle-system modes (the paper's Table 2 baselines) against direct
// computations: a baked map of a ball on a sphere against the ball's exact shadow along the
// normals, and particle splat coverage against a capsule's exact silhouette area.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <string>

#include "render/baselines/particle_mode.h"
#include "render/render_modes.h"
#include "render/baselines/texture_mode.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
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

// The mode's image at 4 spp (64-texel-wide maps) is the same bytes on one thread and on two.
void expect_same_image_on_1_and_2_threads(const Scene& s, RenderMode mode) {
    ModeSettings ms;
    ms.spp = 4;
    ms.texture.width = 64;
    RenderOutput one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = render_in_mode(s, mode, ms).out;
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = render_in_mode(s, mode, ms).out;
    }
    EXPECT_EQ(one.display.rgb, two.display.rgb);
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
    expect_same_image_on_1_and_2_threads(s, RenderMode::kParticles);
}

// A ball of radius 0.3 centred 1.15 above the origin, rooted at its bottom, over `base` (an
// object at the origin); a sphere far off, which must not be taken for the base.
std::string ball_scene(const std::string& base) {
    return R"({
  "camera": {"eye": [0, -6, 3], "look_at": [0, 0, 0.5], "fov_y_deg": 30, "width": 48, "height": 48},
  "lights": [{"position": [4, -5, 6]}],
  "materials": {"skin": {"color": [0.8, 0.5, 0.3]}, "fur": {"color": [0.2, 0.4, 0.6]}},
  "primitives": {"ball": {"spheres": [[0, 0, 0, 0.3]], "cylinders": []}},
  "objects": [{"type": "sphere", "center": [10, 0, 0], "radius": 1, "material": "skin"},
              )" + base + R"(,
              {"type": "instance", "primitive": "ball", "material": "fur",
               "transform": [{"translate": [0, 0, 1.15]}]}]})";
}
const std::string kBallScene =
    ball_scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "skin"})");

TEST(TextureMode, BakedBallMatchesItsExactProjection) {
    const Scene s = load_scene_text(kBallScene, "ball.json");
    TextureOptions opt;
    opt.width = 256;
    opt.subsamples = 4;
    const TextureMaps maps = bake_texture(s, opt);
    EXPECT_EQ(maps.base_object, 1u);
    ASSERT_EQ(maps.atlas->texel_count(), 256u * 128u);
    // Solid angle covered: radial lines meet the ball when 1.15 sin(theta) <= 0.3.
    const double theta0 = std::asin(0.3 / 1.15);
    const double exact = 2 * M_PI * (1 - std::cos(theta0));
    double baked = 0, sphere = 0;
    for (std::size_t t = 0; t < maps.atlas->texel_count(); ++t) {
        baked += maps.atlas->texel_area(t) * maps.coverage(t);
        sphere += maps.atlas->texel_area(t);
        if (maps.coverage(t) == 1) {  // fully covered: the fur's colour
            EXPECT_NEAR(maps.colour_coverage[4 * t] / 255.0, 0.2, 1 / 255.0);
            EXPECT_NEAR(maps.colour_coverage[4 * t + 2] / 255.0, 0.6, 1 / 255.0);
        }
    }
    EXPECT_NEAR(sphere, 4 * M_PI, 1e-9);
    EXPECT_NEAR(baked / exact, 1.0, 0.02);
    // The normal where the line at theta = theta0 / 2 leaves the ball's upper side.
    const double theta = theta0 / 2;
    const Vec3 d{std::sin(theta), 0, std::cos(theta)}, c{0, 0, 1.15};
    const double b = dot(d, c), far = b + std::sqrt(b * b - (dot(c, c) - 0.09));
    const Vec3 n = (d * far - c) / 0.3;
    const TextureMaps::Sample sample = maps.lookup(d, 0, d);
    EXPECT_GT(dot(sample.normal, n), std::cos(3 * M_PI / 180));
    EXPECT_NEAR(sample.coverage, 1.0, 1e-9);
    EXPECT_NEAR(maps.lookup({0, 0, -1}, 0, {0, 0, -1}).coverage, 0.0, 1e-9);
}

// The same ball over a flat square mesh (two triangles, normal +z), with a sphere off to the
// side that the base inference must pass over.
std::string ball_over_mesh(const test::TempDir& dir) {
    test::spit(dir.file("square.obj"), "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nf 1 2 3\nf 1 3 4\n");
    test::spit(dir.file("mesh.json"),
               ball_scene(R"({"type": "mesh", "file": "square.obj", "material": "skin"})"));
    return dir.file("mesh.json");
}

TEST(TextureMode, BakedBallOverAMeshMatchesItsExactProjection) {
    const test::TempDir dir;
    const Scene s = load_scene(ball_over_mesh(dir));
    TextureOptions opt;
    opt.width = 256;
    const TextureMaps maps = bake_texture(s, opt);
    EXPECT_EQ(maps.base_object, 1u);
    // About width^2 / 2 texels of equal area, split between the two triangles.
    EXPECT_NEAR(static_cast<double>(maps.atlas->texel_count()) / (256 * 128), 1.0, 0.01);
    double baked = 0, square = 0;
    for (std::size_t t = 0; t < maps.atlas->texel_count(); ++t) {
        baked += maps.atlas->texel_area(t) * maps.coverage(t);
        square += maps.atlas->texel_area(t);
    }
    EXPECT_NEAR(square, 16, 1e-9);
    // Straight down the normal, the ball covers a disc of its radius.
    EXPECT_NEAR(baked / (M_PI * 0.09), 1.0, 0.02);
    // Under the ball, on both triangles (and on their shared edge), coverage is full and the
    // normal is the ball's where the line down the mesh's normal meets it first; far off, bare.
    for (const Vec3 p : {Vec3{0.1, -0.1, 0}, Vec3{-0.1, 0.1, 0}, Vec3{0, 0, 0}}) {
        const std::uint32_t tri = p.x > p.y ? 0 : 1;
        const TextureMaps::Sample sample = maps.lookup(p, tri, {0, 0, 1});
        const Vec3 top = Vec3{p.x, p.y, std::sqrt(0.09 - p.x * p.x - p.y * p.y)} / 0.3;  // the ball's
        EXPECT_NEAR(sample.coverage, 1.0, 1e-9);
        EXPECT_GT(dot(sample.normal, top), std::cos(3 * M_PI / 180));
        EXPECT_NEAR(sample.colour.y, 0.4, 1 / 255.0);
    }
    EXPECT_NEAR(maps.lookup({1.5, -1, 0}, 0, {0, 0, 1}).coverage, 0.0, 1e-9);
}

TEST(TextureMode, MeshAtlasFindsTheTexelOfItsOwnPoints) {
    const test::TempDir dir;
    const Scene s = load_scene(ball_over_mesh(dir));
    // 200 texels of 0.08: grids of n = sqrt(2 x 8 / 0.08) = 14 on each triangle.
    const auto atlas = make_texture_atlas(s.objects[1], 20);
    ASSERT_EQ(atlas->texel_count(), 2u * 14 * 15 / 2);
    double area = 0;
    for (std::size_t t = 0; t < atlas->texel_count(); ++t) {
        area += atlas->texel_area(t);
        SurfacePoint centre;
        ASSERT_TRUE(atlas->texel_point(t, 0.5, 0.25, centre));  // inside even a diagonal texel
        EXPECT_NEAR(centre.n.z, 1.0, 1e-12);
        const TexelWeights tw = atlas->lookup(centre.p, t < 105 ? 0 : 1);
        double w = 0, own = 0;
        for (int k = 0; k < tw.count; ++k) {
            w += tw.weight[static_cast<std::size_t>(k)];
            if (tw.texel[static_cast<std::size_t>(k)] == t) own += tw.weight[static_cast<std::size_t>(k)];
        }
        EXPECT_NEAR(w, 1.0, 1e-12);
        EXPECT_GT(own, 0.3) << "texel " << t;
    }
    EXPECT_NEAR(area, 16, 1e-9);
}

TEST(TextureMode, MeshImagesAreIdenticalForAnyThreadCount) {
    const test::TempDir dir;
    const Scene s = load_scene(ball_over_mesh(dir));
    expect_same_image_on_1_and_2_threads(s, RenderMode::kTexture);
}

TEST(TextureMode, NeedsASurfaceUnderTheRoots) {
    const Scene s = load_scene_text(capsule_scene(8), "capsule.json");
    try {
        bake_texture(s, {});
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("capsule.json: objects[0]: texture mode"), std::string::npos)
            << e.what();
    }
}

TEST(TextureMode, RefusesFurStandingApartFromTheBase) {
    // Two balls over the sphere at the origin, one over the sphere at x = 10 (objects[3]).
    const Scene s = load_scene_text(
        ball_scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "skin"},
            {"type": "instance", "primitive": "ball", "material": "fur", "transform": [{"translate": [0, 0.1, 1.15]}]},
            {"type": "instance", "primitive": "ball", "material": "fur", "transform": [{"translate": [10, 0, 1.15]}]})"),
        "two.json");
    try {
        texture_base(s);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("two.json: objects[3]: texture mode maps every instance onto the one "
                                             "surface most of them grow from, objects[1]"),
                  std::string::npos)
            << e.what();
    }
}

TEST(TextureMode, ImagesAreIdenticalForAnyThreadCount) {
    const Scene s = load_scene_text(kBallScene, "ball.json");
    expect_same_image_on_1_and_2_threads(s, RenderMode::kTexture);
}

}  // namespace
}  // namespace lat
