// Levels of detail of prefiltered tables: which levels a render reads and builds, within the
// pair budget (memory) and the render's work budget (time), what a primitive past them is
// answered by, and what the summary says; and the footprints that choose the levels.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "geometry/lattice_source.h"
#include "lattice/boundary_grid.h"
#include "lattice/coverage.h"
#include "lattice/filtered_shape.h"
#include "render/modes/scene_lattices.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"

namespace lat {
namespace {

// Two copies of a primitive, one near the camera and one far: levels of detail want 1K, 2K and
// 4K. The primitive is a bead, or a row of six small tori (a CSG union of cost 72, quartics
// counting 12), which costs more to intersect than kMaxExactCost and so is answered by its
// tables and their levels (within the build budget; past it, by its crossings).
constexpr const char* kNearAndFar = R"({
  "format": "lattice-reference/1",
  "camera": {"eye": [1, -3, 1], "look_at": [1, 0.5, 1], "up": [0, 0, 1], "fov_y_deg": 30,
             "width": 16, "height": 16},
  "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": false, "lights": [],
  "materials": {"w": {"color": [1, 1, 1], "ka": 1, "kd": 0, "ks": 0, "shininess": 1}},
  "primitives": {"bead": PRIMITIVE},
  "objects": [{"type": "instance", "primitive": "bead", "material": "w"},
              {"type": "instance", "primitive": "bead",
               "transform": [{"translate": [0, 400, 0]}], "material": "w"}]
})";

std::string near_and_far(bool row, bool far_bead) {
    const std::string lattice = R"("lattice": {"sigma": 1, "cells": [2, 1, 2]})";
    std::string primitive = R"({"spheres": [[1, 0.5, 1, 0.3]], "cylinders": [], )" + lattice + "}";
    if (row) {
        std::string tori;
        for (int i = 0; i < 6; ++i)
            tori += (i ? ", " : "") + std::string(R"({"type": "torus", "center": [)") +
                    std::to_string(0.4 + 0.24 * i) +
                    R"(, 0.5, 1], "axis": [0, 0, 1], "major_radius": 0.3, "minor_radius": 0.05})";
        primitive = R"({"object": {"type": "csg", "op": "union", "children": [)" + tori + "]}, " +
                    lattice + "}";
    }
    std::string text = kNearAndFar;
    text.replace(text.find("PRIMITIVE"), 9, primitive);
    if (!far_bead) {
        text.erase(text.find(",\n              {\"type\": \"instance\""));
        text += "]}";
    }
    return text;
}

// The lattices scene_lattices gives a loaded scene, with coverage tables cached in dir.
SceneLattices lattices_in(const test::TempDir& dir, const Scene& s, const LatticeFiltering& f) {
    const TableCache cache(dir.path().string());
    TableSpec spec;
    spec.encoding = "coverage";
    return scene_lattices(s, cache, spec, false, f);
}

// The lattices scene_lattices gives a scene's one primitive, with levels of detail on, within
// a pair and a work budget, with its cache in dir.
SceneLattices levels_for(const test::TempDir& dir, const std::string& scene, double max_pairs,
                         double max_work = kMaxLodWork,
                         LatticeFilter filter = LatticeFilter::kSmooth) {
    const std::string path = (dir.path() / "near-and-far.json").string();
    std::ofstream(path) << scene;
    return lattices_in(dir, load_scene(path), {filter, true, 0.01, max_pairs, max_work});
}
// How many levels it reads (from a fresh cache).
std::size_t levels_built(const std::string& scene, double max_pairs, double max_work = kMaxLodWork) {
    test::TempDir dir;
    return levels_for(dir, scene, max_pairs, max_work).paths.size();
}

// A costly primitive's shadow rays (coverage only) read its smooth-filtered tables as the box
// filter does, one pair a level: their sheets are the box-filtered lattice's to the bit, while
// its camera rays keep the smooth blend.
TEST(Coverage, ACostlyPrimitivesShadowRaysReadOnePairALevel) {
    test::TempDir dir;
    const std::string scene = near_and_far(true, true);
    const SceneLattices smooth = levels_for(dir, scene, kMaxLodPairs);
    const SceneLattices box = levels_for(dir, scene, kMaxLodPairs, kMaxLodWork, LatticeFilter::kBox);
    ASSERT_EQ(smooth.paths.size(), 3u);  // levels 0 to 2: rays blend two of them
    const Shape& s = *smooth.shapes[0];
    const Shape& b = *box.shapes[0];
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.2, 2.2);
    int shadow_sheets = 0, camera_differ = 0;
    for (int i = 0; i < 4000; ++i) {
        // Across the bead's box (2 x 1 x 2), footprints between its levels' cells.
        const Vec3 o{u(rng), -1.0, u(rng)}, q{u(rng), 2.0, u(rng)};
        for (const bool shadow : {true, false}) {
            RayFootprint f;
            f.width0 = 0.1 + 0.3 * (i % 7) / 7.0;
            f.coverage_only = shadow;
            const Ray r{o, q - o, &f};
            Crossing cs, cb;
            const bool hs = s.intersect(r, 0, kInfinity, cs), hb = b.intersect(r, 0, kInfinity, cb);
            if (!shadow) {
                camera_differ += hs != hb || (hs && cs.coverage != cb.coverage);
                continue;
            }
            ASSERT_EQ(hs, hb) << i;
            if (!hs) continue;
            ++shadow_sheets;
            EXPECT_EQ(cs.coverage, cb.coverage) << i;
            EXPECT_EQ(cs.t, cb.t) << i;
        }
    }
    EXPECT_GT(shadow_sheets, 200);
    EXPECT_GT(camera_differ, 50);
}

// Levels of detail stop at the pair budget (LatticeFiltering::max_pairs): the finest level
// within it serves the rays that want finer; level 0 is built whatever its size. With the far
// copy the scene wants levels 0 to 2, without it level 2 alone.
TEST(Coverage, LevelsOfDetailStopAtThePairBudget) {
    const double p0 = static_cast<double>(BoundaryGrid::pair_count({2, 1, 2}));
    const double p1 = static_cast<double>(BoundaryGrid::pair_count({4, 2, 4}));
    const double p2 = static_cast<double>(BoundaryGrid::pair_count({8, 4, 8}));
    for (const bool far_bead : {true, false}) {
        const auto levels = [&](double max_pairs) {
            return levels_built(near_and_far(true, far_bead), max_pairs);
        };
        // Levels 0-2 (or 2) within the budget; 0-1 (or 1); 0 (or 0).
        const std::size_t all = far_bead ? 3 : 1;
        EXPECT_EQ(levels(kMaxLodPairs), all);
        EXPECT_EQ(levels(p2), all);
        EXPECT_EQ(levels(p2 - 1), far_bead ? 2u : 1u);
        EXPECT_EQ(levels(p1), far_bead ? 2u : 1u);
        EXPECT_EQ(levels(p1 - 1), 1u);
        EXPECT_EQ(levels(p0 / 2), 1u);
    }
}

// Past the work budget (LatticeFiltering::max_work: the render's, spent by every level it
// builds) a costly primitive answers by its own crossings, as a cheap one does (no tables;
// each instance's sub-rays bounded), and says so: the level wanted, the one left out, and why.
TEST(Coverage, PastTheWorkBudgetACostlyPrimitiveAnswersByItsCrossings) {
    const std::string scene = near_and_far(true, true);
    test::TempDir probe;
    const std::string path = (probe.path() / "near-and-far.json").string();
    std::ofstream(path) << scene;
    const Scene loaded = load_scene(path);
    const Shape& bead = *loaded.primitives[0].shape;
    ASSERT_GT(ShapeSource(bead).intersect_cost(), kMaxExactCost);  // its levels are tables
    // The builds' work (a CSG tree: the pairs near its leaves) at sigma^-1 = 1, 2 and 4.
    const int rays = coverage_rays_for(bead);
    const double w0 = coverage_work({{2, 1, 2}, 1.0, 1.0, &bead, rays});
    const double w1 = coverage_work({{4, 2, 4}, 0.5, 1.0, &bead, rays});
    const double w2 = coverage_work({{8, 4, 8}, 0.25, 1.0, &bead, rays});
    ASSERT_LT(w2, static_cast<double>(BoundaryGrid::pair_count({8, 4, 8})) * rays *
                      ShapeSource(bead).intersect_cost());
    ASSERT_GT(w2, w1);
    // Every level the render builds spends from the one budget: all three levels, the finest
    // alone (which cannot pay for level 1 too, so level 0 goes with it), or none.
    const double all = w0 + w1 + w2;
    for (const double budget : {all, w0 + w2, w2 * 0.99, w1 * 0.99, 0.0}) {
        test::TempDir dir;
        const SceneLattices l = levels_for(dir, scene, kMaxLodPairs, budget);
        const std::size_t levels = budget >= all ? 3u : budget >= w2 ? 1u : 0u;
        EXPECT_EQ(l.paths.size(), levels) << budget;
        EXPECT_EQ(l.built, static_cast<int>(levels)) << budget;
        for (const double widest : l.widest_footprints)
            EXPECT_EQ(std::isfinite(widest), levels == 0) << budget;
        ASSERT_EQ(l.notes.size(), levels == 3 ? 0u : 1u) << budget;
        if (levels == 1) {
            EXPECT_NE(l.notes[0].find("sigma^-1 = 2 is over --lod-budget and not in the cache"),
                      std::string::npos)
                << l.notes[0];
        }
        if (levels != 0) continue;
        // The finest level wanted, what it would take, and the budget that builds it.
        const std::string& note = l.notes[0];
        const auto minutes = static_cast<long long>(std::ceil(lod_minutes(w2)));
        for (const std::string& part :
             {std::string("near-and-far.json: primitives.bead: "),
              std::string("from sigma^-1 = 1 to sigma^-1 = 4 wanted"),
              std::string("sigma^-1 = 4 would take about"),
              "--lod-budget " + std::to_string(minutes) + " builds it",
              std::string("its rays take its own crossings instead")})
            EXPECT_NE(note.find(part), std::string::npos) << part << " in " << note;
    }
    // Only the near copy: level 2 alone wanted, past the budget, so crossings, not level 1.
    test::TempDir near;
    const SceneLattices l = levels_for(near, near_and_far(true, false), kMaxLodPairs, w1);
    EXPECT_TRUE(l.paths.empty());
    ASSERT_EQ(l.notes.size(), 1u);
    EXPECT_NE(l.notes[0].find("level of detail sigma^-1 = 4 wanted"), std::string::npos)
        << l.notes[0];
}

// The near-and-far scene with a second primitive, bead2, whose tori have major radius `major2`
// (the first's 0.3), placed as the first is.
std::string two_primitives(const std::string& major2) {
    std::string scene = near_and_far(true, true);
    const std::string head = R"("primitives": {"bead": )";
    const std::size_t from = scene.find(head) + head.size();
    const std::size_t to = scene.find("},\n  \"objects\"");
    EXPECT_NE(to, std::string::npos);
    std::string second = scene.substr(from, to - from);
    second.replace(second.find("0.3, \"minor"), 3, major2);
    scene.insert(to, ", \"bead2\": " + second);
    scene.insert(scene.rfind("}]") + 1,
                 R"(, {"type": "instance", "primitive": "bead2", "material": "w"},
              {"type": "instance", "primitive": "bead2", "transform": [{"translate": [0, 400, 0]}],
               "material": "w"})");
    return scene;
}

// That scene, written into dir and loaded.
Scene two_primitives_scene(const test::TempDir& dir, const std::string& major2) {
    const std::string path = (dir.path() / "two-rows.json").string();
    std::ofstream(path) << two_primitives(major2);
    return load_scene(path);
}

// The builds' work of a primitive's three levels, sigma^-1 = 1, 2 and 4.
double three_levels_work(const Shape& bead) {
    const int rays = coverage_rays_for(bead);
    return coverage_work({{2, 1, 2}, 1.0, 1.0, &bead, rays}) +
           coverage_work({{4, 2, 4}, 0.5, 1.0, &bead, rays}) +
           coverage_work({{8, 4, 8}, 0.25, 1.0, &bead, rays});
}

// The budget is the render's: the levels of a second primitive wanting the same get only what
// the first left (here nothing past the lattice asked for, which is read whatever it costs),
// and its note says what the first spent.
TEST(Coverage, TheWorkBudgetIsSharedByThePrimitives) {
    test::TempDir dir;
    const Scene s = two_primitives_scene(dir, "0.29");
    ASSERT_EQ(s.primitives.size(), 2u);
    const double all = three_levels_work(*s.primitives[0].shape);
    const SceneLattices l = lattices_in(
        dir, s, {LatticeFilter::kSmooth, true, 0.01, kMaxLodPairs, all * 1.001, LatticePolicy::kTables});
    ASSERT_EQ(l.answers.size(), 2u);
    EXPECT_EQ(l.answers[0].sigma_inv, (std::vector<long long>{1, 2, 4}));
    EXPECT_EQ(l.answers[1].sigma_inv, (std::vector<long long>{1}));
    EXPECT_EQ(l.answers[1].coverage_rays, kCostlyRays);
    ASSERT_EQ(l.notes.size(), 1u);
    EXPECT_NE(l.notes[0].find("primitives.bead2"), std::string::npos) << l.notes[0];
    EXPECT_NE(l.notes[0].find("of it spent on the primitives before"), std::string::npos)
        << l.notes[0];
    ASSERT_EQ(l.builds.size(), 4u);
    EXPECT_EQ(l.builds[0].coverage_rays, kCostlyRays);
    EXPECT_GT(l.builds[0].estimated_cpu_seconds, 0);
}

// In auto mode a primitive over the budget answers by its crossings and builds nothing, so it
// spends nothing: a second, smaller primitive gets the whole budget for its finest level, which
// it could not afford had the first spent on the coarser levels it left unread.
TEST(Coverage, APrimitiveAnsweredByItsCrossingsSpendsNoBudget) {
    test::TempDir dir;
    const Scene s = two_primitives_scene(dir, "0.1");
    ASSERT_EQ(s.primitives.size(), 2u);
    const auto work = [&](std::size_t prim, int level) {
        const Shape& shape = *s.primitives[prim].shape;
        const int n = 2 << level;
        return coverage_work({{n, n / 2, n}, 1.0 / (1 << level), 1.0, &shape, coverage_rays_for(shape)});
    };
    const double budget = 0.99 * work(0, 2);  // the first's finest level is over it
    ASSERT_LT(work(1, 2), budget);
    ASSERT_GT(work(1, 2), budget - work(0, 0) - work(0, 1));
    const SceneLattices l = lattices_in(
        dir, s, {LatticeFilter::kSmooth, true, 0.01, kMaxLodPairs, budget, LatticePolicy::kAuto});
    ASSERT_EQ(l.answers.size(), 2u);
    EXPECT_EQ(l.answers[0].by, AnsweredBy::kSubRayCrossings);
    EXPECT_EQ(l.answers[1].by, AnsweredBy::kFilteredTables);
    ASSERT_FALSE(l.answers[1].sigma_inv.empty());
    EXPECT_EQ(l.answers[1].sigma_inv.back(), 4);
}

// Levels left out for their size (the pair budget) are said too, with what their rays read.
TEST(Coverage, LevelsLeftOutForTheirSizeAreSaid) {
    test::TempDir dir;
    const double p1 = static_cast<double>(BoundaryGrid::pair_count({4, 2, 4}));
    const SceneLattices l = levels_for(dir, near_and_far(true, true), p1);
    EXPECT_EQ(l.paths.size(), 2u);
    ASSERT_EQ(l.notes.size(), 1u);
    for (const std::string part : {"sigma^-1 = 4 has", "M pairs, over the budget of",
                                   "rays that want finer read sigma^-1 = 2"})
        EXPECT_NE(l.notes[0].find(part), std::string::npos) << part << " in " << l.notes[0];
}

// The work budget bounds what a render builds, not what it reads: levels in the cache are read
// whatever it is, and the levels between them too only when they are cached or within it.
TEST(Coverage, LevelsOfDetailInTheCacheAreReadWhateverTheWorkBudget) {
    test::TempDir dir;
    const std::string scene = near_and_far(true, true);
    EXPECT_EQ(levels_for(dir, scene, kMaxLodPairs).paths.size(), 3u);  // builds all three
    const SceneLattices cached = levels_for(dir, scene, kMaxLodPairs, 0);
    EXPECT_EQ(cached.paths.size(), 3u);
    EXPECT_EQ(cached.built, 0);
    EXPECT_TRUE(cached.notes.empty());
    // Level 1 gone from the cache: level 2 alone is read (level 1 is not affordable), and
    // nothing is built.
    std::filesystem::remove(cached.paths[1]);
    const SceneLattices gap = levels_for(dir, scene, kMaxLodPairs, 0);
    ASSERT_EQ(gap.paths.size(), 1u);
    EXPECT_EQ(gap.paths[0], cached.paths[2]);
    EXPECT_EQ(gap.built, 0);
    ASSERT_EQ(gap.notes.size(), 1u);
    EXPECT_NE(gap.notes[0].find("sigma^-1 = 2 is over --lod-budget and not in the cache; rays "
                                "that want coarser read sigma^-1 = 4"),
              std::string::npos)
        << gap.notes[0];
    // Level 2 gone too: past the budget, the primitive answers by its crossings.
    std::filesystem::remove(cached.paths[2]);
    const SceneLattices none = levels_for(dir, scene, kMaxLodPairs, 0);
    EXPECT_TRUE(none.paths.empty());
    EXPECT_EQ(none.notes.size(), 1u);
}

// The footprints on a primitive's copies: from the nearest point of the nearest box to the
// farthest of the farthest, in the primitive's units (a copy scaled by 1/2 doubles them); none
// for a primitive without copies.
TEST(Coverage, FootprintsRangeOverTheCopiesBoxesInPrimitiveUnits) {
    test::TempDir dir;
    const std::string path = (dir.path() / "copies.json").string();
    std::ofstream(path) << R"({
  "camera": {"eye": [1, -10, 1], "look_at": [1, 0, 1], "up": [0, 0, 1], "fov_y_deg": 30,
             "width": 16, "height": 16},
  "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": false, "lights": [],
  "materials": {"w": {"color": [1, 1, 1], "ka": 1, "kd": 0, "ks": 0, "shininess": 1}},
  "primitives": {"bead": {"spheres": [[1, 0.5, 1, 0.3]], "cylinders": [],
                          "lattice": {"sigma": 1, "cells": [2, 1, 2]}},
                 "unused": {"spheres": [[1, 0.5, 1, 0.3]], "cylinders": [],
                            "lattice": {"sigma": 1, "cells": [2, 1, 2]}}},
  "objects": [{"type": "instance", "primitive": "bead", "material": "w"},
              {"type": "instance", "primitive": "bead", "material": "w",
               "transform": [{"scale": 0.5}, {"translate": [0, 100, 0]}]}]
})";
    const Scene s = load_scene(path);
    const TableContext base{{2, 1, 2}, 1.0, 1.0, nullptr};
    const double spread = 0.01;
    const auto [lo, hi] = footprint_range(s, 0, base, spread);
    // The near copy's box: centre 10.5 from the eye, half-diagonal 1.5; the far one's: centre
    // (0.5, 100.25, 0.5), half-diagonal 0.75, 2 primitive units a world unit.
    EXPECT_NEAR(lo, (10.5 - 1.5) * spread, 1e-12);
    EXPECT_NEAR(hi, (std::sqrt(0.5 + 110.25 * 110.25) + 0.75) * spread * 2, 1e-12);
    const auto [none_lo, none_hi] = footprint_range(s, 1, base, spread);
    EXPECT_GT(none_lo, none_hi);
}

// A primitive cheap to intersect is answered by its own crossings, however near and far its
// copies: no ray reads its tables, and none is built, unless a CSG tree holds a copy (its spans
// are point-sampled from the lattice asked for, which alone is built).
TEST(Coverage, PrimitivesAnsweredByTheirCrossingsBuildATableOnlyForCsg) {
    const std::string copies = near_and_far(false, true);
    EXPECT_EQ(levels_built(copies, kMaxLodPairs), 0u);
    std::string with_tree = copies;
    with_tree.insert(with_tree.rfind(']'),
                     R"(, {"type": "csg", "op": "union", "material": "w", "children": [)"
                     R"({"type": "instance", "primitive": "bead", "transform": [)"
                     R"({"translate": [0, 0, 3]}]}, {"type": "sphere", "center": [5, 5, 5],)"
                     R"( "radius": 0.5}]})");
    EXPECT_EQ(levels_built(with_tree, kMaxLodPairs), 1u);
}

}  // namespace
}  // namespace lat
