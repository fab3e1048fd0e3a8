// Rendering against exact computations: a lit sphere by hand, thread-count independence,
// instanced against flattened acceleration, and supersampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <tbb/task_arena.h>

#include <cmath>

#include "render/core/camera.h"
#include "render/modes/integrators.h"
#include "scene/scene_loader.h"
#include "test_paths.h"

namespace lat {
namespace {

const char* kSphereScene = R"({
  "camera": {"eye": [0, -6, 1], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_y_deg": 30,
             "width": 64, "height": 48},
  "background": [0.1, 0.2, 0.3], "ambient": [0.5, 0.5, 0.5], "shadows": true,
  "lights": [{"position": [4, -5, 6], "intensity": [0.9, 0.8, 0.7]},
             {"position": [-6, -2, 1], "intensity": 0.4}],
  "materials": {"m": {"color": [0.8, 0.5, 0.3], "ka": 0.2, "kd": 0.7, "ks": 0.5, "shininess": 15}},
  "objects": [{"type": "sphere", "center": [0.2, 0.1, 0.05], "radius": 1.1, "material": "m"}]})";

// Pixel (i, j)'s camera ray and where it first meets the scene's one sphere, computed
// directly (the camera's rule, docs/scene-format.md).
struct SphereHit {
    Vec3 d, p, n;  // the unit ray direction, the hit point, the unit normal
    bool hit = false;
};
SphereHit sphere_hit(const Scene& s, int i, int j) {
    const Camera& c = s.camera;
    const Vec3 w = normalize(c.look_at - c.eye), u = normalize(cross(w, c.up)), v = cross(u, w);
    const double h = std::tan(c.fov_y_deg * M_PI / 360), a = double(c.width) / c.height;
    SphereHit out;
    out.d = normalize(w + (2 * (i + 0.5) / c.width - 1) * a * h * u +
                      (1 - 2 * (j + 0.5) / c.height) * h * v);
    const Vec3 center{0.2, 0.1, 0.05};
    const double r = 1.1;
    const Vec3 oc = c.eye - center;
    const double b = dot(oc, out.d), disc = b * b - (dot(oc, oc) - r * r);
    if (disc < 0) return out;
    out.p = c.eye + out.d * (-b - std::sqrt(disc));
    out.n = normalize(out.p - center);
    out.hit = true;
    return out;
}

// The reference rule evaluated directly for one sphere (no other object can shadow it; the
// sphere shadows itself exactly where N.L < 0, which the rule then zeroes anyway except for
// the specular term).
Vec3 expected_pixel(const Scene& s, int i, int j) {
    const SphereHit sh = sphere_hit(s, i, j);
    if (!sh.hit) return s.background;
    const Vec3 p = sh.p, n = sh.n, vv = -sh.d;
    const Material& m = s.materials[0];
    Vec3 col = m.ka * m.color * s.ambient;
    for (const PointLight& l : s.lights) {
        const Vec3 L = normalize(l.position - p);
        const double nl = dot(n, L);
        if (nl < 0) continue;  // the sphere itself is in the way
        const Vec3 R = 2 * nl * n - L;
        const double spec = m.ks * std::pow(std::max(0.0, dot(R, vv)), m.shininess);
        col += l.intensity * (m.kd * nl * m.color + Vec3{spec, spec, spec});
    }
    return col;
}

TEST(Render, LitSphereMatchesTheShadingRule) {
    const Scene s = load_scene_text(kSphereScene, "sphere.json");
    const TracedScene rs(s);
    const RenderOutput out = render_exact(rs, {});
    int checked = 0;
    for (int j = 0; j < s.camera.height; ++j) {
        for (int i = 0; i < s.camera.width; ++i) {
            const Vec3 e = expected_pixel(s, i, j);
            for (std::size_t ch = 0; ch < 3; ++ch) {
                const std::size_t k = (static_cast<std::size_t>(j) * s.camera.width + i) * 3 + ch;
                ASSERT_NEAR(out.radiance.rgb[k], e[ch], 1e-5) << i << "," << j;
                ASSERT_EQ(out.display.rgb[k], to_byte(e[ch])) << i << "," << j;
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 64 * 48 * 3);
}

// A light that adds nothing at a hit (N.L and R.V both at most 0) casts no shadow ray there;
// every other light at every hit casts one. Counted by the reference rule, as above.
TEST(Render, LightsThatAddNothingCastNoShadowRay) {
    const Scene s = load_scene_text(kSphereScene, "sphere.json");
    const RenderOutput out = render_exact(TracedScene(s), {});
    std::uint64_t pairs = 0, adding = 0;
    for (int j = 0; j < s.camera.height; ++j)
        for (int i = 0; i < s.camera.width; ++i) {
            const SphereHit sh = sphere_hit(s, i, j);
            if (!sh.hit) continue;
            for (const PointLight& l : s.lights) {
                const Vec3 L = normalize(l.position - sh.p);
                const double nl = dot(sh.n, L);
                ++pairs;
                adding += nl > 0 || dot(2 * nl * sh.n - L, -sh.d) > 0;
            }
        }
    ASSERT_GT(pairs - adding, 100u);  // the scene has surfaces turned from a light
    // Exact: at every hit max(N.L, R.V) is at least 3.9e-4 from 0, far beyond rounding.
    EXPECT_EQ(out.stats.shadow_rays, adding);
}

Scene small_plate(const char* name, int size) {
    Scene s = load_scene(test::source_path(std::string("examples/") + name));
    s.camera.width = s.camera.height = size;
    return s;
}

Image8 render_with_threads(const TracedScene& rs, int threads) {
    tbb::task_arena arena(threads);
    Image8 img;
    arena.execute([&] { img = render_exact(rs, {}).display; });
    return img;
}

TEST(Render, IdenticalBytesForAnyThreadCount) {
    const Scene s = small_plate("plate4-fuzzy-sphere-1000.json", 96);
    const TracedScene rs(s);
    const Image8 one = render_with_threads(rs, 1);
    const Image8 two = render_with_threads(rs, 2);
    const Image8 four = render_with_threads(rs, 4);
    EXPECT_EQ(one.rgb, two.rgb);
    EXPECT_EQ(one.rgb, four.rgb);
}

TEST(Render, InstancedAndFlattenedAgree) {
    const Scene s = small_plate("plate2-thistle.json", 96);
    AccelOptions inst, flat;
    inst.instancing = Instancing::kAlways;
    flat.instancing = Instancing::kNever;
    const TracedScene a(s, {}, inst), b(s, {}, flat);
    const Image8 ia = render_exact(a, {}).display;
    EXPECT_EQ(ia.rgb, render_exact(b, {}).display.rgb);
    // Not two blank images: the thistle covers a good part of the frame, whose corner is
    // background.
    std::size_t covered = 0;
    for (std::size_t i = 0; i + 2 < ia.rgb.size(); i += 3)
        covered += std::equal(ia.rgb.begin() + i, ia.rgb.begin() + i + 3, ia.rgb.begin()) ? 0 : 1;
    EXPECT_GT(covered, ia.rgb.size() / 3 / 10);
}

// An instance of a CSG primitive as a leaf of a CSG object: a tree inside a tree. Its cut faces
// must shade with the subtracted sphere's normal (turned) and the leaves' own materials, as
// the same tree written out in place does.
TEST(Render, TreesAsCsgLeavesShadeAsWrittenOut) {
    const std::string head = R"({
      "camera": {"eye": [7, -9, 6], "look_at": [0, 0, 0.6], "fov_y_deg": 32, "width": 96, "height": 72},
      "lights": [{"position": [10, -6, 14], "intensity": 0.9}],
      "materials": {"gold": {"color": [0.85, 0.62, 0.2], "ks": 0.6, "shininess": 40},
                    "blue": {"color": [0.2, 0.3, 0.9]}},
      "primitives": {"bite": {"object": BITE, "lattice": {"sigma": 1, "cells": [7, 7, 3]}}},
      "objects": [{"type": "csg", "op": "union", "material": "gold",
                   "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 20}}], "children": [
        LEAF,
        {"type": "sphere", "center": [0, 0, 1.8], "radius": 0.6, "material": "blue"}]}]})";
    const std::string bite = R"({"type": "csg", "op": "difference",
        "transform": [{"translate": [3.5, 3.5, 1.5]}], "children": [
          {"type": "torus", "major_radius": 2.2, "minor_radius": 0.85},
          {"type": "sphere", "center": [1.6, -1.6, 0.5], "radius": 1.25}]})";
    auto scene = [&](const std::string& leaf) {
        std::string t = head;
        t.replace(t.find("BITE"), 4, bite);
        t.replace(t.find("LEAF"), 4, leaf);
        return load_scene_text(t, "trees.json");
    };
    const Scene nested = scene(R"({"type": "instance", "primitive": "bite",
                                    "transform": [{"translate": [-3.5, -3.5, -1.5]}]})");
    std::string inline_bite = bite;
    inline_bite.replace(inline_bite.find("[3.5, 3.5, 1.5]"), 15, "[0, 0, 0]");
    const Scene written = scene(inline_bite);
    const Image8 a = render_exact(TracedScene(nested), {}).display;
    const Image8 b = render_exact(TracedScene(written), {}).display;
    int differ = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) differ += std::abs(a.rgb[i] - b.rgb[i]) > 1;
    EXPECT_EQ(differ, 0);
}

TEST(Render, SupersamplingAveragesAnEdge) {
    // A wall (y >= 0) cut to x >= 0 by CSG, seen head-on: its edge runs down the middle of the
    // centre column, so stratified samples give that column half the wall's colour.
    const char* scene = R"({
      "camera": {"eye": [0, -10, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_y_deg": 10,
                 "width": 9, "height": 9},
      "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": false,
      "materials": {"white": {"color": [1, 1, 1], "ka": 1, "kd": 0, "ks": 0}},
      "objects": [{"type": "csg", "op": "intersection", "material": "white", "children": [
                   {"type": "halfspace", "normal": [0, -1, 0]},
                   {"type": "halfspace", "normal": [-1, 0, 0]}]}]})";
    const Scene s = load_scene_text(scene, "edge.json");
    const TracedScene rs(s);
    RenderOptions opt;
    opt.spp = 64;
    const RenderOutput out = render_exact(rs, opt);
    // Column 4 is centred on x = 0; an 8 x 8 stratified grid puts exactly half its samples on
    // each side.
    for (int j = 0; j < 9; ++j) {
        EXPECT_NEAR(out.radiance.rgb[(j * 9 + 4) * 3], 0.5, 1e-6);
        EXPECT_EQ(out.radiance.rgb[(j * 9 + 0) * 3], 0.0f);
        EXPECT_EQ(out.radiance.rgb[(j * 9 + 8) * 3], 1.0f);
    }
}

TEST(Render, StratifiedGrid) {
    int nx, ny;
    stratify(16, nx, ny);
    EXPECT_EQ(nx * ny, 16);
    EXPECT_EQ(nx, 4);
    stratify(8, nx, ny);
    EXPECT_EQ(nx * ny, 8);
    stratify(7, nx, ny);
    EXPECT_EQ(nx * ny, 7);
}

}  // namespace
}  // namespace lat
