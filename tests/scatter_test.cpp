// Scatter objects: counts for a density, uniformity by area (chi-square over equal-area bins),
// roots on the surface and frames along the normal, Poisson-disk spacing, determinism, errors.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "input_error.h"
#include "render/modes/integrators.h"
#include "scene/scatter.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "test_paths.h"
#include "io/image.h"
#include "util/hash.h"
#include "util/memory.h"

namespace lat {
namespace {

// The first root of the scatter in DeterministicForASeedAndAnyThreadCount, in units of 1e-9.
const char* const kFirstRoot = "-687205162 142361934 1325700624";

// A hair whose lattice base centre is (1, 1, 0): the root the scatter puts on the surface.
const char* kHead = R"({
  "camera": {"eye": [0, -12, 3], "look_at": [0, 0, 0], "fov_y_deg": 30, "width": 64, "height": 64},
  "lights": [{"position": [5, -6, 8]}],
  "materials": {"skin": {"color": [0.8, 0.6, 0.5]}, "fur": {"color": [0.4, 0.3, 0.2]}},
  "primitives": {"hair": {"spheres": [[1, 1, 0.1, 0.1], [1, 1, 1.5, 0.05]], "cylinders": [[0, 1, 0.05]],
                          "lattice": {"sigma": 0.25, "cells": [8, 8, 7]}}},
  "objects": [)";

Scene load(const std::string& objects) {
    return load_scene_text(std::string(kHead) + objects + "]}", "scatter.json");
}

// Roots of the instances of the scene's first scatter, in world space.
std::vector<Vec3> roots(const Scene& s) {
    std::vector<Vec3> out;
    const ScatterGroup& g = s.scatters.at(0);
    for (std::size_t i = g.first; i < g.first + g.count; ++i) out.push_back(s.transform(i).point({1, 1, 0}));
    return out;
}

// Pearson's statistic; `expected` sums to the count.
double chi_square(const std::vector<int>& observed, const std::vector<double>& expected) {
    double x = 0;
    for (std::size_t i = 0; i < observed.size(); ++i)
        x += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    return x;
}

// The 1 % critical value of chi-square with k degrees of freedom (Wilson-Hilferty).
double chi_square_1pct(int k) {
    const double z = 2.3263478740408408, a = 2.0 / (9 * k);
    return k * std::pow(1 - a + z * std::sqrt(a), 3);
}

TEST(Scatter, DensityGivesTheCountForTheArea) {
    // Sphere of radius 2: area 16 pi.
    const Scene s = load(R"({"type": "sphere", "name": "head", "radius": 2, "material": "skin"},
        {"type": "scatter", "primitive": "hair", "on": "head", "density": 40, "material": "fur"})");
    ASSERT_EQ(s.scatters.size(), 1u);
    EXPECT_NEAR(double(s.scatters[0].count), 40 * 16 * M_PI, 0.02 * 40 * 16 * M_PI);
    EXPECT_NEAR(double(s.scatters[0].count), 40 * 16 * M_PI, 2.0);  // in fact exactly rounded
    // A cylinder of radius 0.5 clipped to height 3 by the box: area 3 pi; a torus 4 pi² R r.
    const Scene c = load(R"({"type": "scatter", "primitive": "hair", "density": 100, "material": "fur",
        "on": {"type": "cylinder", "radius": 0.5, "axis": [1, 0, 0], "material": "skin"},
        "box": [[-1.5, -5, -5], [1.5, 5, 5]]})");
    EXPECT_NEAR(double(c.scatters[0].count), 300 * M_PI, 0.005 * 300 * M_PI);
    const Scene t = load(R"({"type": "scatter", "primitive": "hair", "density": 30, "material": "fur",
        "on": {"type": "torus", "major_radius": 2, "minor_radius": 0.5, "material": "skin",
               "transform": [{"scale": 1.5}]}})");
    const double area = 4 * M_PI * M_PI * 3 * 0.75;
    EXPECT_NEAR(double(t.scatters[0].count), 30 * area, 0.005 * 30 * area);
}

TEST(Scatter, UniformByAreaOnASphere) {
    const Scene s = load(R"({"type": "sphere", "name": "head", "center": [1, 2, 3], "radius": 2, "material": "skin"},
        {"type": "scatter", "primitive": "hair", "on": "head", "count": 8000, "seed": 7, "material": "fur"})");
    const std::vector<Vec3> r = roots(s);
    ASSERT_EQ(r.size(), 8000u);
    // 10 slabs of equal height are of equal area (Archimedes), times 8 sectors: 80 bins.
    std::vector<int> bins(80, 0);
    for (const Vec3& p : r) {
        const Vec3 q = (p - Vec3{1, 2, 3}) / 2;
        ASSERT_NEAR(length(q), 1, 1e-12);
        const int zb = std::min(9, int((q.z + 1) / 0.2));
        const int ab = std::min(7, int((std::atan2(q.y, q.x) + M_PI) / (M_PI / 4)));
        ++bins[std::size_t(zb * 8 + ab)];
    }
    EXPECT_LT(chi_square(bins, std::vector<double>(80, 100.0)), chi_square_1pct(79));
}

TEST(Scatter, UniformByAreaOnATorusAndAMesh) {
    // Torus R = 2, r = 0.5: the outer half of the tube holds more area, (R + r cos v) dv.
    const Scene t = load(R"({"type": "scatter", "primitive": "hair", "count": 6000, "material": "fur",
        "on": {"type": "torus", "major_radius": 2, "minor_radius": 0.5, "material": "skin"}})");
    std::vector<int> bins(12, 0);
    for (const Vec3& p : roots(t)) {
        const double rho = std::hypot(p.x, p.y);
        ASSERT_NEAR(std::hypot(rho - 2, p.z), 0.5, 1e-9);
        const double v = std::atan2(p.z, rho - 2) + M_PI;
        ++bins[std::size_t(std::min(11, int(v / (M_PI / 6))))];
    }
    std::vector<double> expected;
    for (int k = 0; k < 12; ++k) {
        const double v0 = k * M_PI / 6 - M_PI, v1 = v0 + M_PI / 6;
        expected.push_back(6000 * (2 * (v1 - v0) + 0.5 * (std::sin(v1) - std::sin(v0))) / (4 * M_PI));
    }
    EXPECT_LT(chi_square(bins, expected), chi_square_1pct(11));

    // A box mesh stretched to 1 x 2 x 3: each face gets hairs in proportion to its area.
    const test::TempDir dir;
    test::spit(dir.file("box.obj"),
               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
               "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n"
               "f 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n");
    test::spit(dir.file("s.json"), std::string(kHead) + R"({"type": "mesh", "name": "m", "file": "box.obj",
        "material": "skin", "transform": [{"scale": [1, 2, 3]}]},
        {"type": "scatter", "primitive": "hair", "on": "m", "count": 6000, "material": "fur", "tilt_deg": 0}]})");
    const Scene m = load_scene(dir.file("s.json"));
    std::vector<int> faces(3, 0);  // by axis of the face normal
    for (const Vec3& p : roots(m)) {
        const double dx = std::min(p.x, 1 - p.x), dy = std::min(p.y, 2 - p.y), dz = std::min(p.z, 3 - p.z);
        ++faces[dx < dy && dx < dz ? 0 : (dy < dz ? 1 : 2)];
    }
    // Faces across x: 2 x 2 x 3 = 12, across y: 2 x 1 x 3 = 6, across z: 2 x 1 x 2 = 4.
    EXPECT_LT(chi_square(faces, {6000.0 * 12 / 22, 6000.0 * 6 / 22, 6000.0 * 4 / 22}), chi_square_1pct(2));
}

TEST(Scatter, RootsOnTheSurfaceAlongTheNormal) {
    const Scene s = load(R"({"type": "scatter", "primitive": "hair", "count": 200, "material": "fur",
        "twist": 30, "scale": [0.5, 2], "on": {"type": "sphere", "radius": 3, "material": "skin"}})");
    for (std::size_t i = s.scatters[0].first; i < s.object_count(); ++i) {
        const Transform xf = s.transform(i);
        const Vec3 root = xf.point({1, 1, 0});
        const Vec3 up = xf.vector({0, 0, 1});
        EXPECT_NEAR(length(root), 3, 1e-12);
        EXPECT_NEAR(dot(normalize(up), root / 3), 1, 1e-12);  // no tilt: along the normal
        EXPECT_GE(length(up), 0.5 - 1e-12);
        EXPECT_LE(length(up), 2 + 1e-12);
        EXPECT_EQ(s.primitive_of(i), 0);
    }
    // With a tilt, the axis stays within it of the normal.
    const Scene t = load(R"({"type": "scatter", "primitive": "hair", "count": 500, "material": "fur",
        "tilt_deg": 20, "on": {"type": "sphere", "radius": 3, "material": "skin"}})");
    double widest = 0;
    for (std::size_t i = t.scatters[0].first; i < t.object_count(); ++i) {
        const Transform xf = t.transform(i);
        const double c = dot(normalize(xf.vector({0, 0, 1})), normalize(xf.point({1, 1, 0})));
        widest = std::max(widest, std::acos(std::min(1.0, c)) * 180 / M_PI);
    }
    EXPECT_LE(widest, 20 + 1e-9);
    EXPECT_GT(widest, 15);
}

TEST(Scatter, PoissonDiskKeepsItsDistance) {
    const Scene s = load(R"({"type": "scatter", "primitive": "hair", "count": 1500, "material": "fur",
        "min_distance": 0.06, "on": {"type": "halfspace", "normal": [0, 0, 1], "material": "skin"},
        "box": [[-2, -2, -1], [2, 2, 1]]})");
    const std::vector<Vec3> r = roots(s);
    ASSERT_EQ(r.size(), 1500u);
    for (std::size_t i = 0; i < r.size(); ++i) {
        EXPECT_NEAR(r[i].z, 0, 1e-12);
        EXPECT_LE(std::max(std::abs(r[i].x), std::abs(r[i].y)), 2);
        for (std::size_t j = 0; j < i; ++j) ASSERT_GE(length(r[i] - r[j]), 0.06);
    }
}

// The placements as bytes: what "deterministic" is about.
std::uint64_t placement_hash(const Scene& s) {
    std::vector<double> v;
    for (std::size_t i = 0; i < s.object_count(); ++i) {
        const Affine a = s.transform(i).forward();
        for (std::size_t r = 0; r < 3; ++r) {
            for (std::size_t c = 0; c < 3; ++c) v.push_back(a.m.r[r][c]);
            v.push_back(a.t[r]);
        }
    }
    return hash_bytes(v.data(), v.size() * sizeof(double));
}

TEST(Scatter, DeterministicForASeedAndAnyThreadCount) {
    const std::string objs = R"({"type": "scatter", "primitive": "hair", "count": 300, "seed": 11,
        "material": "fur", "tilt_deg": 25, "scale": [0.8, 1.2], "poisson": true,
        "on": {"type": "sphere", "radius": 1.5, "material": "skin"}})";
    std::uint64_t h1 = 0, h2 = 0;
    Image8 i1, i2;
    tbb::task_arena(1).execute([&] {
        const Scene s = load(objs);
        h1 = placement_hash(s);
        i1 = render_exact(TracedScene(s), {}).display;
    });
    tbb::task_arena(2).execute([&] {
        const Scene s = load(objs);
        h2 = placement_hash(s);
        i2 = render_exact(TracedScene(s), {}).display;
    });
    EXPECT_EQ(h1, h2);
    EXPECT_EQ(i1.rgb, i2.rgb);
    // Another seed moves them.
    std::string other = objs;
    other.replace(other.find("\"seed\": 11"), 10, "\"seed\": 12");
    EXPECT_NE(placement_hash(load(other)), h1);
    // And the roots are the same numbers on every machine: the first one, to 1e-9.
    const Scene s = load(objs);
    const Vec3 p = s.transform(1).point({1, 1, 0});
    EXPECT_EQ(std::to_string(std::llround(p.x * 1e9)) + " " + std::to_string(std::llround(p.y * 1e9)) +
                  " " + std::to_string(std::llround(p.z * 1e9)),
              kFirstRoot);
}

TEST(Scatter, BadParametersAreInputErrors) {
    auto error = [](const std::string& objs) { return test::error_of([&] { load(objs); }); };
    const std::string sphere = R"("on": {"type": "sphere", "radius": 1, "material": "skin"})";
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "material": "fur", )" + sphere + "}")
                  .find("objects[0]: a scatter needs exactly one of 'count' or 'density'"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": -3, "material": "fur", )" + sphere + "}")
                  .find("objects[0].count: must not be negative"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "density": 1e12, "material": "fur", )" + sphere + "}")
                  .find("objects[0].density: 12566370614359 instances is over the limit"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "on": "nobody"})")
                  .find("objects[0].on: no object is named 'nobody'"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur",
                        "on": {"type": "cylinder", "radius": 1, "material": "skin"}})")
                  .find("objects[0]: missing field 'box': a cylinder is unbounded"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur",
                        "on": {"type": "quartic", "polynomial": "x^4+y^4+z^4-1", "material": "skin"}})")
                  .find("objects[0].on.type: cannot scatter over a quartic"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "tilt_deg": 100, )" + sphere + "}")
                  .find("objects[0].tilt_deg: must be between 0 and 90"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 40, "material": "fur", "min_distance": 1, )" + sphere + "}")
                  .find("objects[0].min_distance: only"), std::string::npos);
    // Counts that no packing fits into the surface's bounds, and distances too small to file
    // points by, are refused before any dart is thrown (5000 once took 50 tries an instance).
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5000, "material": "fur", "min_distance": 1, )" + sphere + "}")
                  .find("objects[0].min_distance: 5000 instances cannot be 1 apart on this surface: its bounds hold "
                        "at most 51 points that far apart"), std::string::npos);
    // Scales whose placement overflows or underflows are refused (Scene::transform inverts
    // each placement, and once found none).
    for (const char* scale : {"1e300", "1e-300", "[1e-300, 2e-300]"})
        EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "scale": )" +
                        std::string(scale) + ", " + sphere + "}")
                      .find(" has no invertible finite placement: a scale of "),
                  std::string::npos)
            << scale;
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "scale": 1e300, )" + sphere + "}")
                  .find("objects[0].scale: instance 0 has no invertible finite placement: a scale of 1e+300 is too extreme"),
              std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "min_distance": 1e-300, )" + sphere + "}")
                  .find("objects[0].min_distance: a minimum distance of 1e-300 is too small for a surface 2 across"),
              std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "box": [[5, 5, 5], [6, 6, 6]],
                        "on": {"type": "halfspace", "normal": [0, 0, 1], "material": "skin"}})")
                  .find("objects[0].box: the box holds none of the surface"), std::string::npos);
    // Without a box, an area that overflows is not blamed on one (it was "the box holds none").
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur",
                        "on": {"type": "sphere", "radius": 1e200, "material": "skin"}})")
                  .find("objects[0]: the surface's area, placed, is not a finite number"), std::string::npos);
    EXPECT_NE(error(R"({"type": "scatter", "primitive": "hair", "count": 5, "material": "fur", "on": 3})")
                  .find("objects[0].on: object index 3 does not exist"), std::string::npos);
}

// A mesh whose placed area underflows to zero or overflows is refused at the scatter's `on`,
// with the file and place (the sampler's own message had neither).
TEST(Scatter, MeshWithoutAFiniteAreaIsALocatedError) {
    const test::TempDir dir;
    test::spit(dir.file("tet.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    const std::string path = dir.file("s.json");
    auto error = [&](const char* scale) {
        test::spit(path, std::string(kHead) + R"({"type": "mesh", "name": "m", "file": "tet.obj",
            "material": "skin", "transform": [{"scale": )" + scale + R"(}]},
            {"type": "scatter", "primitive": "hair", "on": "m", "count": 5, "material": "fur"}]})");
        return test::error_of([&] { load_scene(path); });
    };
    EXPECT_NE(error("1e150").find(path + ": objects[1].on: the mesh's area, placed, is not a finite number"),
              std::string::npos);
    EXPECT_NE(error("1e-150").find(path + ": objects[1].on: the mesh has no area to scatter on"), std::string::npos);
}

// A count within the limit that the memory available cannot hold is refused before anything
// is placed (on a machine with less than 49 GB available; elsewhere the test has no case).
TEST(Scatter, CountsOverTheMemoryAvailableAreInputErrors) {
    const std::size_t count = 49'000'000;
    if (available_memory_bytes() == 0 || available_memory_bytes() >= count * kScatterBytesPerInstance)
        GTEST_SKIP() << "this machine could hold " << count << " instances";
    const std::string e = test::error_of([&] {
        load(R"({"type": "scatter", "primitive": "hair", "count": 49000000, "material": "fur",
                 "on": {"type": "sphere", "radius": 1, "material": "skin"}})");
    });
    EXPECT_NE(e.find("objects[0].count: 49000000 instances need about 49.0 GB of memory with the objects before them, over the "),
              std::string::npos) << e;
}

TEST(Scatter, CommandWritesExplicitInstancesThatRenderTheSameImage) {
    const test::TempDir dir;
    const std::string scene = test::source_path("tests/data/bad/scatter-mesh-good.json");
    const std::string placed = dir.file("placed.json");
    const std::string cmd = test::lattice_binary() + " scatter " + scene + " -o " + placed + " > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const Scene a = load_scene(scene), b = load_scene(placed);
    ASSERT_EQ(a.object_count(), b.object_count());
    EXPECT_TRUE(b.scatters.empty());
    EXPECT_EQ(placement_hash(a), placement_hash(b));  // the mesh path was moved to stay found
    EXPECT_EQ(render_exact(TracedScene(a), {}).display.rgb, render_exact(TracedScene(b), {}).display.rgb);
}

}  // namespace
}  // namespace lat
