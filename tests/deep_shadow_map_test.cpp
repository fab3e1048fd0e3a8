// Deep shadow maps of the instances (render/deep_shadow_map.h, render/instance_shadows.h):
// against the exact shadow of a ball, and in a layered render of fur against its shadow rays.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <string>

#include "render/deep_shadow_map.h"
#include "render/render_modes.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

// One ball of radius 1 at the origin, an instance of a one-sphere primitive, lit from above.
Scene ball_scene(Vec3 light) {
    return load_scene_text(R"({"camera": {"eye": [0, -10, 0], "look_at": [0, 0, 0], "fov_y_deg": 30,
            "width": 16, "height": 16},
        "lights": [{"position": [)" + std::to_string(light.x) + ", " + std::to_string(light.y) +
                               ", " + std::to_string(light.z) + R"(]}],
        "materials": {"m": {}},
        "primitives": {"ball": {"spheres": [[0, 0, 0, 1]], "cylinders": []}},
        "objects": [{"type": "instance", "primitive": "ball", "material": "m"}]})",
                           "ball.json");
}

Bounds3 ball_bounds() { return {{-1, -1, -1}, {1, 1, 1}}; }

TEST(DeepShadowMap, AnOpaqueBallShadowsWhatLiesBehindItAndNothingElse) {
    const Scene s = ball_scene({0, 0, 10});
    const TracedScene rs(s);  // the ball traced exactly: an opaque instance
    MapBudget budget(1 << 20);
    const DeepShadowMap map(rs, {0, 0, 10}, ball_bounds(), 128, "lights[0]", budget);
    ASSERT_TRUE(map.valid());
    const double bias = 1e-3;
    EXPECT_EQ(map.transmittance({0, 0, -3}, bias), 0);      // straight behind the ball
    EXPECT_EQ(map.transmittance({0.3, -0.2, -1.5}, bias), 0);
    EXPECT_EQ(map.transmittance({0, 0, 2}, bias), 1);       // between the light and the ball
    EXPECT_EQ(map.transmittance({0, 0, 1}, bias), 1);       // its own lit top
    EXPECT_EQ(map.transmittance({3, 0, -3}, bias), 1);      // beside its shadow
    EXPECT_EQ(map.transmittance({0, 0, 0.999}, 0.1), 1);    // under its surface, within the bias
    EXPECT_EQ(map.transmittance({0, 0, 0.5}, bias), 0);     // inside, past the bias
    EXPECT_EQ(map.transmittance({0, 0, 0.5}, bias, 0), 1);  // on the ball itself: its own
    // Across the edge of the shadow the light rises from 0 to 1 within about a texel, at the
    // cone the ball casts: at distance z below the light, radius (10 - z) / sqrt(99).
    const double at = 13 / std::sqrt(99.0), texel = map.texel_width(13);
    EXPECT_EQ(map.transmittance({at - 2 * texel, 0, -3}, bias), 0);
    EXPECT_EQ(map.transmittance({at + 2 * texel, 0, -3}, bias), 1);
    double previous = 0;
    for (int k = -20; k <= 20; ++k) {
        const double t = map.transmittance({at + 0.1 * k * texel, 0, -3}, bias);
        EXPECT_GE(t, previous - 1e-12);
        previous = t;
    }
    EXPECT_GT(map.tiles_traced(), 0u);
    EXPECT_LT(map.tiles_traced(), map.tiles());  // tiles no lookup asked for are not traced
    EXPECT_EQ(budget.used.load(), map.bytes());
}

TEST(DeepShadowMap, MapsPastTheirBudgetAreRefusedNamingTheLight) {
    const Scene s = ball_scene({0, 0, 10});
    const TracedScene rs(s);
    MapBudget small(1000);  // not even the index of 64 x 64 tiles
    EXPECT_THROW(DeepShadowMap(rs, {0, 0, 10}, ball_bounds(), 1024, "lights[0]", small), InputError);
    MapBudget ample(1 << 30);
    { const DeepShadowMap sized(rs, {0, 0, 10}, ball_bounds(), 1024, "lights[0]", ample); }
    MapBudget index_only(ample.used + 1);  // its tiles' index, and not one tile traced
    const DeepShadowMap map(rs, {0, 0, 10}, ball_bounds(), 1024, "lights[0]", index_only);
    try {
        for (int k = 0; k < 64; ++k) map.transmittance({0.02 * k - 0.6, 0, -3}, 1e-3);
        FAIL() << "no error past the budget";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("ball.json: lights[0]: its deep shadow map"),
                  std::string::npos) << e.what();
    }
}

TEST(DeepShadowMap, ALightAmongTheInstancesHasNoMap) {
    const Scene s = ball_scene({0, 0, 0.5});
    const TracedScene rs(s);
    MapBudget budget(1 << 20);
    const DeepShadowMap map(rs, {0, 0, 0.5}, ball_bounds(), 64, "lights[0]", budget);
    EXPECT_FALSE(map.valid());
    EXPECT_EQ(map.transmittance({0, 0, -3}, 0), 1);
}

// A ball of fur (400 hairs on a sphere of radius 2) on a floor (a sphere of radius 100), with
// these lights (JSON).
const char* const kTwoLights = R"([{"position": [6, -8, 10]},
    {"position": [-8, 4, 6], "intensity": [0.4, 0.4, 0.4]}])";
Scene fur_scene(const std::string& lights) {
    return load_scene_text(R"({
  "camera": {"eye": [0, -12, 4], "look_at": [0, 0, 0.5], "fov_y_deg": 35, "width": 64, "height": 64},
  "lights": )" + lights + R"(,
  "materials": {"skin": {"color": [0.8, 0.6, 0.5]}, "fur": {"color": [0.9, 0.8, 0.6]},
                "floor": {"color": [0.6, 0.7, 0.8]}},
  "primitives": {"hair": {"spheres": [[1, 1, 0.1, 0.1], [1, 1, 1.5, 0.05]], "cylinders": [[0, 1, 0.05]],
                          "lattice": {"sigma": 0.25, "cells": [8, 8, 7]}}},
  "objects": [{"type": "sphere", "name": "head", "center": [0, 0, 1], "radius": 2, "material": "skin"},
              {"type": "sphere", "center": [0, 0, -100], "radius": 100, "material": "floor"},
              {"type": "scatter", "primitive": "hair", "on": "head", "count": 400, "seed": 3,
               "material": "fur"}]})",
                           "fur.json");
}

// Lattice mode, smooth-filtered tables at sigma^-1 = 1 alone (quick to build), in `cache`.
ModeResult render_fur(const Scene& s, InstanceShadowing shadows, const test::TempDir& cache) {
    ModeSettings ms;
    ms.lattice_dir = cache.path().string();
    ms.spec.encoding = "coverage";
    ms.filtering.filter = LatticeFilter::kSmooth;
    ms.filtering.lod = false;
    ms.instance_shadows = shadows;
    ms.shadow_map_size = 512;
    return render_in_mode(s, RenderMode::kLattice, ms);
}

double mean_abs_difference(const Image8& a, const Image8& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) sum += std::abs(double(a.rgb[i]) - double(b.rgb[i]));
    return sum / double(a.rgb.size());
}

// Exact mode at 16 spp, shadows by rays: the truth both are measured against.
RenderOutput fur_truth(const Scene& s) {
    ModeSettings ms;
    ms.spp = 16;
    return render_in_mode(s, RenderMode::kExact, ms).out;
}

TEST(DeepShadowMap, FurShadowedByItsMapsIsAsFaithfulAsFurShadowedByRays) {
    Scene s = fur_scene(kTwoLights);
    const test::TempDir cache;
    const RenderOutput truth = fur_truth(s);
    const ModeResult rays = render_fur(s, InstanceShadowing::kRays, cache);
    const ModeResult maps = render_fur(s, InstanceShadowing::kDeepMap, cache);
    ASSERT_TRUE(maps.shadow_maps);
    EXPECT_FALSE(rays.shadow_maps);
    EXPECT_EQ(maps.shadow_maps->lights_mapped, 2u);
    EXPECT_GT(maps.shadow_maps->tiles_traced, 0u);
    EXPECT_GT(maps.shadow_maps->knots, 0u);
    s.shadows = false;
    const ModeResult unshadowed = render_fur(s, InstanceShadowing::kDeepMap, cache);
    EXPECT_FALSE(unshadowed.shadow_maps);  // no shadows: no maps
    const double by_rays = mean_abs_difference(rays.out.display, truth.display);
    const double by_maps = mean_abs_difference(maps.out.display, truth.display);
    const double none = mean_abs_difference(unshadowed.out.display, truth.display);
    EXPECT_GT(none, 1.5 * by_rays);  // the shadows show
    EXPECT_LT(by_maps, 1.05 * by_rays);
}

TEST(DeepShadowMap, TheImageIsTheSameOnOneThreadAndTwo) {
    const Scene s = fur_scene(kTwoLights);
    const test::TempDir cache;
    RenderOutput one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = render_fur(s, InstanceShadowing::kDeepMap, cache).out;
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = render_fur(s, InstanceShadowing::kDeepMap, cache).out;
    }
    EXPECT_EQ(one.display.rgb, two.display.rgb);
}

TEST(DeepShadowMap, ALightAmongTheInstancesKeepsItsShadowRays) {
    const Scene s = fur_scene(R"([{"position": [0.5, -0.5, 2.5]}])");  // within the fur's sphere
    const test::TempDir cache;
    const ModeResult rays = render_fur(s, InstanceShadowing::kRays, cache);
    const ModeResult maps = render_fur(s, InstanceShadowing::kDeepMap, cache);
    ASSERT_TRUE(maps.shadow_maps);
    EXPECT_EQ(maps.shadow_maps->lights, 1u);
    EXPECT_EQ(maps.shadow_maps->lights_mapped, 0u);
    EXPECT_EQ(maps.out.display.rgb, rays.out.display.rgb);
}

TEST(DeepShadowMap, NoInstancesOrNoLightsMakeNoMaps) {
    const test::TempDir cache;
    Scene lightless = fur_scene("[]");
    EXPECT_FALSE(render_fur(lightless, InstanceShadowing::kDeepMap, cache).shadow_maps);
    Scene bare = load_scene_text(R"({"camera": {"eye": [0, -10, 0], "look_at": [0, 0, 0],
        "fov_y_deg": 30, "width": 16, "height": 16}, "lights": [{"position": [0, 0, 10]}],
        "materials": {"m": {}}, "objects": [{"type": "sphere", "radius": 1, "material": "m"}]})",
                                 "bare.json");
    const ModeResult r = render_fur(bare, InstanceShadowing::kDeepMap, cache);
    EXPECT_FALSE(r.shadow_maps);
}

// Hairs written out as instance objects around a head, and a floor: instances first, or the
// head and floor first. The maps' knots name instances as the scene numbers them, and a point
// on a hair leaves its own out by that number: the image must not depend on the order. (The
// base's own numbering, by which a point on the head skips the head's crossings, shows only
// where those lie past the shadow rays' epsilon, as on meshes; it is not tested here.)
Scene written_out(bool instances_first) {
    std::string hairs, base = R"({"type": "sphere", "center": [0, 0, 1], "radius": 2, "material": "skin"},
        {"type": "sphere", "center": [0, 0, -100], "radius": 100, "material": "floor"})";
    for (int k = 0; k < 12; ++k) {
        const double a = k * 0.5236;
        hairs += R"({"type": "instance", "primitive": "hair", "material": "fur", "transform": [)"
                 R"({"rotate": {"axis": [1, 0, 0], "angle_deg": 40}}, {"rotate": {"axis": [0, 0, 1], "angle_deg": )" +
                 std::to_string(k * 30) + R"(}}, {"translate": [)" + std::to_string(std::cos(a) * 0.5 - 1) +
                 ", " + std::to_string(std::sin(a) * 0.5 - 1) + R"(, 2.9]}]},)";
    }
    hairs.pop_back();
    const std::string objects = instances_first ? hairs + ", " + base : base + ", " + hairs;
    return load_scene_text(R"({
  "camera": {"eye": [0, -12, 4], "look_at": [0, 0, 1.5], "fov_y_deg": 25, "width": 48, "height": 48},
  "lights": [{"position": [6, -8, 10]}],
  "materials": {"skin": {"color": [0.8, 0.6, 0.5]}, "fur": {"color": [0.9, 0.8, 0.6]},
                "floor": {"color": [0.6, 0.7, 0.8]}},
  "primitives": {"hair": {"spheres": [[1, 1, 0.1, 0.1], [1, 1, 1.5, 0.05]], "cylinders": [[0, 1, 0.05]],
                          "lattice": {"sigma": 0.25, "cells": [8, 8, 7]}}},
  "objects": [)" + objects + "]}",
                           "written-out.json");
}

TEST(DeepShadowMap, TheImageDoesNotDependOnTheOrderOfObjects) {
    const test::TempDir cache;
    const ModeResult first = render_fur(written_out(true), InstanceShadowing::kDeepMap, cache);
    const ModeResult last = render_fur(written_out(false), InstanceShadowing::kDeepMap, cache);
    ASSERT_TRUE(first.shadow_maps);
    EXPECT_GT(first.shadow_maps->knots, 0u);
    EXPECT_LT(mean_abs_difference(first.out.display, last.out.display), 0.05);
}

}  // namespace
}  // namespace lat
