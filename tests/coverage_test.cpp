// Coverage: a prefiltered table's alpha for a pair is the share of the rays snapping
// to the pair that meet the primitive, checked against brute force (random rays, snapped by the
// renderer's own LatticeFrame); and a primitive thinner than a cell, rendered through filtered
// lattices at 1 sample per pixel, has the brightness of a supersampled exact render.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "csg/csg_shape.h"
#include "geometry/chain.h"
#include "geometry/lattice_source.h"
#include "geometry/named_shapes.h"
#include "geometry/sphere.h"
#include "coverage_checks.h"
#include "hook_primitive.h"
#include "lattice/boundary_grid.h"
#include "lattice/coverage.h"
#include "lattice/coverage_rays.h"
#include "lattice/encoding.h"
#include "lattice/filtered_shape.h"
#include "lattice/lattice_shape.h"
#include "lattice/rasterizer.h"
#include "render/core/camera.h"
#include "render/modes/integrators.h"
#include "render/modes/scene_lattices.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"

namespace lat {
namespace {

using test::hook;
const TableContext& kContext = test::kHookContext;

// Of rays parallel to the segment a b, shifted uniformly over the face cell of a, those the
// renderer snaps to (a, b), the share whose chord through the box meets the primitive (the whole
// primitive, exactly); -1 if too few snap.
double brute_force_alpha(const CoverageSample& c, std::mt19937_64& rng) {
    const BoundaryGrid grid(kContext.cells);
    const LatticeFrame frame(kContext, kInfinity);
    const GridPoint ga = grid.point(c.a), gb = grid.point(c.b);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    int snapped = 0, hit = 0;
    for (int i = 0; i < 4000; ++i) {
        const auto [p, q] = coverage_ray(grid, ga, gb, u(rng), u(rng));
        const Ray r{p * kContext.cell, (q - p) * kContext.cell};
        LatticeFrame::Snap s;
        if (!frame.snap(r, s) || s.a != c.a || s.b != c.b) continue;
        ++snapped;
        Crossing x;
        hit += hook().intersect(r, 0.0, 1.0, x) || hook().inside(r.o);
    }
    return snapped < 1000 ? -1.0 : double(hit) / snapped;
}

TEST(Coverage, AlphaMatchesBruteForceSubSampling) {
    const std::vector<CoverageSample> all = rasterize_coverage(kContext, false);
    ASSERT_GT(all.size(), 1000u);
    std::mt19937_64 rng(7);
    int partial = 0, checked = 0;
    for (std::size_t i = 0; i < all.size(); i += all.size() / 60) {
        const CoverageSample& c = all[i];
        const double brute = brute_force_alpha(c, rng);
        if (brute < 0) continue;  // a pair on an edge, whose cells reach onto other faces
        ++checked;
        partial += c.alpha < 1;
        EXPECT_NEAR(c.alpha, brute, 0.08) << c.a << " -> " << c.b;
    }
    EXPECT_GT(checked, 30);
    EXPECT_GT(partial, 10);
}

TEST(Coverage, CullingLosesNoPair) {
    // The rasterized coverage (parts culled by cones) equals intersecting every sub-ray with the
    // whole primitive, and no pair with enough hits is missing.
    const std::vector<CoverageSample> all = rasterize_coverage(kContext, false);
    const BoundaryGrid grid(kContext.cells);
    std::size_t next = 0;
    for (std::uint32_t a = 0; a < grid.count(); a += 5)
        for (std::uint32_t b = 0; b < grid.count(); b += 3) {
            if (a == b || !BoundaryGrid::valid_pair(grid.faces(grid.point(a)), grid.faces(grid.point(b))))
                continue;
            const CoverageSample ref = pair_coverage(kContext, a, b);
            next = static_cast<std::size_t>(std::lower_bound(all.begin(), all.end(), ref,
                                                             [](const CoverageSample& x, const CoverageSample& y) {
                                                                 return x.a != y.a ? x.a < y.a : x.b < y.b;
                                                             }) - all.begin());
            const bool listed = next < all.size() && all[next].a == a && all[next].b == b;
            ASSERT_EQ(listed, ref.alpha >= kCoverageMinAlpha) << a << " -> " << b;
            if (!listed) continue;
            EXPECT_EQ(all[next].alpha, ref.alpha);
            EXPECT_EQ(all[next].t, ref.t);
        }
}

// Three tori minus a sphere in a 4 x 4 x 4 box of cell 1 (the burr of the costly-primitive
// bench, smaller): a CSG tree, whose pairs the build culls by its leaves.
const CsgShape& small_burr() {
    static const std::shared_ptr<CsgShape> csg = [] {
        auto c = std::make_shared<CsgShape>();
        std::vector<int> tori;
        for (const Vec3 axis : {Vec3{1, 0.2, 0}, Vec3{0, 1, 0.3}, Vec3{0.3, 0, 1}}) {
            const PlacedShape t = make_torus({2, 2, 2}, normalize(axis), 1.4, 0.2);
            tori.push_back(c->add_leaf({t.shape, t.placement, 0}));
        }
        const int ring = c->add_node(CsgOp::kUnion, tori);
        const int bite = c->add_leaf({std::make_shared<SphereShape>(Vec3{2, 2, 3.2}, 0.9), {}, 0});
        c->set_root(c->add_node(CsgOp::kDifference, {ring, bite}));
        return c;
    }();
    return *csg;
}

TEST(Coverage, CullingByLeavesLosesNoPair) {
    // A CSG tree's pairs are culled by its leaves' spheres and its sub-rays evaluate the leaves
    // near them alone: every pair's coverage is still the definition's to the bit (the whole
    // tree, every sub-ray snapped), and no pair with enough hits is left out.
    const TableContext ctx{{4, 4, 4}, 1.0, 1.0, &small_burr()};
    const std::vector<CoverageSample> all = rasterize_coverage(ctx, false);
    const BoundaryGrid grid(ctx.cells);
    const auto before = [](const CoverageSample& x, const CoverageSample& y) {
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    };
    int listed_pairs = 0, unlisted = 0;
    for (std::uint32_t a = 0; a < grid.count(); a += 2)
        for (std::uint32_t b = 0; b < grid.count(); ++b) {
            if (a == b || !BoundaryGrid::valid_pair(grid.faces(grid.point(a)), grid.faces(grid.point(b))))
                continue;
            const CoverageSample ref = pair_coverage(ctx, a, b);
            const auto it = std::lower_bound(all.begin(), all.end(), ref, before);
            const bool listed = it != all.end() && it->a == a && it->b == b;
            ASSERT_EQ(listed, ref.alpha >= kCoverageMinAlpha) << a << " -> " << b;
            if (!listed) {
                ++unlisted;
                continue;
            }
            ++listed_pairs;
            EXPECT_EQ(it->alpha, ref.alpha) << a << " -> " << b;
            EXPECT_EQ(it->t, ref.t) << a << " -> " << b;
            EXPECT_EQ(it->nu, ref.nu) << a << " -> " << b;
            EXPECT_EQ(it->nv, ref.nv) << a << " -> " << b;
        }
    EXPECT_GT(listed_pairs, 1000);
    EXPECT_GT(unlisted, 1000);
}

TEST(Coverage, GuessedSnapsAreSnaps) {
    // The build guesses most sub-rays' snaps from their ends (PairRays::guess_snap): wherever it
    // answers, on every sub-ray of every pair of a lattice and on shifts up to the cell's edge,
    // LatticeFrame::snap agrees. (On lattices this small many pairs lie along the box's faces
    // and edges, where it leaves the answer to snap: a third of them here, a few percent of the
    // sub-rays of the hair at sigma^-1 = 2.)
    for (const TableContext& ctx : {kContext, TableContext{{5, 3, 7}, 1.0, 1.0, &hook()}}) {
        const BoundaryGrid grid(ctx.cells);
        const LatticeFrame frame(ctx, kInfinity);
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u(-0.5, 0.5);
        std::uint64_t guessed = 0, unsure = 0;
        for (std::uint32_t a = 0; a < grid.count(); ++a)
            for (std::uint32_t b = 0; b < grid.count(); ++b) {
                const GridPoint ga = grid.point(a), gb = grid.point(b);
                if (a == b || !BoundaryGrid::valid_pair(grid.faces(ga), grid.faces(gb))) continue;
                const PairRays pr(grid, ga, gb);
                for (int k = 0; k < kCoverageRays + 8; ++k) {
                    const SubRay s = k < kCoverageRays ? coverage_ray(grid, ga, gb, k, kCoverageRays)
                                                        : pr.ray(u(rng), u(rng));
                    const PairRays::Snap g = pr.guess_snap(s);
                    if (g == PairRays::Snap::kUnsure) {
                        ++unsure;
                        continue;
                    }
                    ++guessed;
                    LatticeFrame::Snap sn;
                    const bool snapped = frame.snap({s.p * ctx.cell, (s.q - s.p) * ctx.cell}, sn) &&
                                         sn.a == a && sn.b == b;
                    ASSERT_EQ(snapped, g == PairRays::Snap::kPair) << a << " -> " << b << " ray " << k;
                }
            }
        EXPECT_LT(unsure, guessed);
    }
}

TEST(Coverage, TheTableAnswersTheCoverage) {
    ASSERT_TRUE(find_encoding("coverage").coverage);
    const test::BuiltCoverageTable b = test::expect_table_answers_coverage(kContext);
    EXPECT_NE(b.table->details().find("partly covered"), std::string::npos);
}

// The lookups the smooth filter makes (coverage_many: locate_coverage, then coverage_at, as the
// filtered shape calls them) find exactly the stored pairs, with or without their normals.
TEST(Coverage, ManyLookupsFindExactlyTheStoredPairs) {
    const Encoding& e = find_encoding("coverage");
    const RasterizeResult r = rasterize(kContext);
    const ByteBuffer payload = e.build(r.raw, kContext, {});
    const auto table = e.open(payload.data(), payload.size(), r.hits, kContext);
    const std::uint32_t n = BoundaryGrid(kContext.cells).count();
    std::vector<std::uint8_t> stored(std::size_t{n} * n, 0);
    for (const CoverageSample& c : rasterize_coverage(kContext, false))
        stored[std::size_t{c.a} * n + c.b] = c.alpha > 0;
    int found_pairs = 0;
    for (std::uint32_t a = 0; a < n; ++a)
        for (std::uint32_t b0 = 0; b0 < n; b0 += 5) {
            std::uint32_t as[5], bs[5];
            for (int i = 0; i < 5; ++i) as[i] = a, bs[i] = std::min(b0 + std::uint32_t(i), n);
            CoverageHit with[5], without[5];
            bool f1[5], f2[5];
            table->coverage_many(as, bs, 5, with, f1, true);
            table->coverage_many(as, bs, 5, without, f2, false);
            for (int i = 0; i < 5; ++i) {
                const bool want = bs[i] < n && stored[std::size_t{a} * n + bs[i]];
                ASSERT_EQ(f1[i], want) << a << " " << bs[i];
                ASSERT_EQ(f2[i], want);
                if (!want) continue;
                ++found_pairs;
                EXPECT_EQ(with[i].alpha, without[i].alpha);
                EXPECT_EQ(with[i].t, without[i].t);
                // A mean of unit normals: no longer than 1, shorter where they spread.
                EXPECT_LE(length(with[i].normal), 1.0 + 1e-9);
            }
        }
    EXPECT_GT(found_pairs, 100);
}

// The hook's coverage table behind the smooth filter, with the bytes the table reads.
struct SmoothHook {
    RasterizeResult rasterized;
    ByteBuffer payload;
    std::unique_ptr<FilteredLatticeShape> shape;
};

SmoothHook smooth_hook() {
    const Encoding& e = find_encoding("coverage");
    SmoothHook h{rasterize(kContext), {}, nullptr};
    h.payload = e.build(h.rasterized.raw, kContext, {});
    std::shared_ptr<const LatticeTable> table =
        e.open(h.payload.data(), h.payload.size(), h.rasterized.hits, kContext);
    h.shape = std::make_unique<FilteredLatticeShape>(std::vector<FilterLevel>{{table, kContext}},
                                                     LatticeFilter::kSmooth,
                                                     e.error_bound(kContext, {}));
    return h;
}

// How much coverage culling loses: rays the accelerator turns away get no sheet, even where the
// filter would cover a little of them. A two-level lattice of a primitive (sigma 1 and 1/2, the
// hook's box) is culled by its finer level's frame, cutting the filters short of their bound
// (filtered_shape.cpp). Rays: lines from outside the box, or rays starting inside it (shadow
// rays among fur); footprints that read the coarse level alone (its filter is cut most) or the
// fine one alone. Returns the share of the coverage lost and how many rays culling turned away.
struct CullLoss {
    double lost = 0;
    int turned_away = 0;
};
// A primitive's coverage tables at sigma 1 and 1/2 in the hook's box, with the bytes they read.
struct TwoLevels {
    std::vector<ByteBuffer> payloads;
    std::vector<FilterLevel> levels;
    double error = 0;  // the finer level's Encoding::error_bound
};
TwoLevels two_levels(const Shape& primitive) {
    const Encoding& e = find_encoding("coverage");
    TwoLevels t;
    t.payloads.reserve(2);  // the tables read the payloads in place
    for (const double cell : {1.0, 0.5}) {
        const int m = cell < 1 ? 2 : 1;
        const TableContext ctx{{4 * m, 2 * m, 4 * m}, cell, 1.0, &primitive};
        const RasterizeResult r = rasterize(ctx);
        t.payloads.push_back(e.build(r.raw, ctx, {}));
        t.levels.push_back(
            {e.open(t.payloads.back().data(), t.payloads.back().size(), r.hits, ctx), ctx});
        t.error = e.error_bound(ctx, {});
    }
    return t;
}
CullLoss cull_loss(const TwoLevels& t, LatticeFilter filter, bool inside, double footprint) {
    const FilteredLatticeShape shape(t.levels, filter, t.error);
    // As the accelerator (EmbreeAccel's first_visit): a cull part's box, then, where the object
    // has several parts, its test.
    auto kept = [&](const Ray& r) {
        const std::size_t n = shape.cull_count();
        for (std::size_t i = 0; i < n; ++i) {
            double t0 = 0, t1 = kInfinity;
            if (clip_ray(shape.cull_bounds(i, Transform{}, kInfinity), r, t0, t1) &&
                (n == 1 || shape.cull_meets(i, r)))
                return true;
        }
        return false;
    };
    RayFootprint f;
    f.width0 = footprint;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> g(0.0, 1.0);
    const Bounds3 box = shape.bounds(), around = expand(box, 1.0);
    auto point = [&](const Bounds3& b) { return b.lo + Vec3{u(rng), u(rng), u(rng)} * (b.hi - b.lo); };
    double total = 0, lost = 0;
    CullLoss out;
    for (int i = 0; i < 20000; ++i) {
        Ray ray;
        if (inside) {
            const Vec3 d{g(rng), g(rng), g(rng)};
            ray = {point(box), d / length(d), &f};
        } else {
            const Vec3 p = point(around), q = point(around);
            ray = {p - (q - p), (q - p) / length(q - p), &f};
        }
        Crossing c;
        const double alpha = shape.intersect(ray, 0.0, kInfinity, c) ? double(c.coverage) : 0.0;
        total += alpha;
        if (kept(ray)) continue;
        ++out.turned_away;
        lost += alpha;
    }
    EXPECT_GT(total, 100.0);
    out.lost = lost / total;
    return out;
}

// The bars: the smooth filter loses at most 3.4e-4 in these cases (4.1e-3 if its tent were cut
// at 1.5 cells, 5.6 % at 0.5), `box` 1.4e-3 (its coarse level's reach is cut to the fine one's),
// rays that read the culling level itself nothing measurable.
TEST(Coverage, CullingKeepsNearlyAllTheCoverage) {
    // A hair 0.16 coarse cells thick, as well as the hook (one cell thick).
    const double r = 0.08;
    const ChainShape thin({{{0.7, 1.0, 0.6}, r}, {{2.0, 1.1, 2.2}, r}, {{3.3, 0.9, 3.4}, r}},
                          {{0, 1, r}, {1, 2, r}});
    for (const Shape* primitive : {static_cast<const Shape*>(&hook()), static_cast<const Shape*>(&thin)}) {
        const TwoLevels tables = two_levels(*primitive);
        for (const LatticeFilter f : {LatticeFilter::kSmooth, LatticeFilter::kBox})
            for (const bool inside : {false, true})
                for (const double footprint : {2.0, 1e-4}) {
                    const CullLoss l = cull_loss(tables, f, inside, footprint);
                    const double most = footprint < 1 ? 1e-5 : (f == LatticeFilter::kBox ? 3e-3 : 1e-3);
                    EXPECT_LT(l.lost, most) << (primitive == &thin ? "thin hair" : "hook") << ", filter "
                                            << int(f) << (inside ? ", rays inside" : ", lines")
                                            << ", footprint " << footprint;
                    EXPECT_GT(l.turned_away, 500);
                }
    }
}

// Shadow rays ask for the coverage alone (RayFootprint::coverage_only): the same sheets, where
// they lie and how much they cover, as for camera rays.
TEST(Coverage, ShadowRaysGetTheSameSheetsWithoutNormals) {
    const SmoothHook hook_lattice = smooth_hook();
    const FilteredLatticeShape& shape = *hook_lattice.shape;
    std::mt19937_64 rng(7);
    const Bounds3 box = shape.bounds();
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto point = [&] {
        return box.lo + Vec3{u(rng), u(rng), u(rng)} * (box.hi - box.lo);
    };
    RayFootprint coverage_only;
    coverage_only.coverage_only = true;
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 p = point(), q = point();
        const Ray ray{p - (q - p), (q - p) / length(q - p)};
        Crossing camera, shadow;
        const bool h1 = shape.intersect(ray, 0.0, kInfinity, camera);
        const bool h2 = shape.intersect({ray.o, ray.d, &coverage_only}, 0.0, kInfinity, shadow);
        ASSERT_EQ(h1, h2);
        if (!h1) continue;
        ++hits;
        EXPECT_EQ(camera.t, shadow.t);
        EXPECT_EQ(camera.coverage, shadow.coverage);
    }
    EXPECT_GT(hits, 100);
}

// A ray that starts inside the box (a shadow ray leaving a surface among fur) between two
// crossings of the primitive, one behind it and one ahead: its pairs' first crossings lie
// behind it, and the sheet is made of their last crossings (the reversed pairs), so that the
// primitive still blocks it. Before, the sheet lay behind the start and the ray went through.
TEST(Coverage, ARayStartingBetweenTwoCrossingsIsStillBlocked) {
    const SmoothHook hook_lattice = smooth_hook();
    const FilteredLatticeShape& shape = *hook_lattice.shape;
    std::mt19937_64 rng(11);
    const Bounds3 box = shape.bounds();
    std::uniform_real_distribution<double> u(0.0, 1.0);
    RayFootprint coverage_only;
    coverage_only.coverage_only = true;
    int between = 0, blocked = 0;
    for (int i = 0; i < 200000 && between < 300; ++i) {
        const Vec3 o = box.lo + Vec3{u(rng), u(rng), u(rng)} * (box.hi - box.lo);
        const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        Crossing ahead, behind;
        // Clear of the primitive on both sides by half a cell.
        if (hook().inside(o) || !hook().intersect({o, d}, 0.5 * kContext.cell, kInfinity, ahead) ||
            !hook().intersect({o, -d}, 0.5 * kContext.cell, kInfinity, behind) ||
            hook().intersect({o, d}, 0.0, 0.5 * kContext.cell, ahead) ||
            hook().intersect({o, -d}, 0.0, 0.5 * kContext.cell, behind))
            continue;
        ++between;
        Crossing c;
        blocked += shape.intersect({o, d, &coverage_only}, 1e-9, kInfinity, c) && c.t > 0 &&
                   c.coverage >= 0.5f;
    }
    ASSERT_GE(between, 100);
    EXPECT_GT(double(blocked) / between, 0.8) << blocked << " of " << between;
}

// A ray that starts among a pair's crossings (a shadow ray leaving a point among fur) meets
// the share of them ahead of its start: none a half spread behind their mean, half at it, all
// a half spread ahead, linearly between (so a shadow no longer jumps where the mean passes the
// start).
TEST(Coverage, ARayMeetsTheShareOfAPairsCrossingsAheadOfItsStart) {
    const double spread = 2.0;
    EXPECT_EQ(crossing_share_ahead(-1.0, spread), 0.0);
    EXPECT_EQ(crossing_share_ahead(-5.0, spread), 0.0);
    EXPECT_DOUBLE_EQ(crossing_share_ahead(-0.5, spread), 0.25);
    EXPECT_DOUBLE_EQ(crossing_share_ahead(0.0, spread), 0.5);
    EXPECT_DOUBLE_EQ(crossing_share_ahead(0.5, spread), 0.75);
    EXPECT_EQ(crossing_share_ahead(1.0, spread), 1.0);
    EXPECT_EQ(crossing_share_ahead(7.0, spread), 1.0);
}

// A hair of radius 0.15 in cells of 1, across the view, 2.3 pixels a cell.
const char* kThinHair = R"({
  "camera": {"eye": [3, -60, 4], "look_at": [3, 0, 4], "up": [0, 0, 1], "fov_y_deg": 10, "width": 96, "height": 96},
  "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": false,
  "lights": [{"position": [3, -60, 4], "intensity": [1, 1, 1]}],
  "materials": {"w": {"color": [1, 1, 1], "ka": 1, "kd": 0, "ks": 0, "shininess": 1}},
  "primitives": {"thin": {"spheres": [[1.5, 1.3, 1.5, 0.15], [4.5, 1.3, 3.2, 0.15], [1.5, 1.3, 6.5, 0.15]],
                          "cylinders": [[0, 1, 0.15], [1, 2, 0.15]],
                          "lattice": {"sigma": 1, "cells": [6, 3, 8]}}},
  "objects": [{"type": "instance", "primitive": "thin", "transform": [{"rotate": {"axis": [0, 1, 0], "angle_deg": 7}}], "material": "w"}]
})";

double mean_brightness(const Image8& im) {
    double sum = 0;
    for (const std::uint8_t v : im.rgb) sum += v;
    return sum / static_cast<double>(im.rgb.size());
}

// The scene (JSON) rendered through its filtered lattices, box then smooth, at 1 spp: each
// image's mean brightness over exact mode's at 64 spp. check(rs) runs on each filter's scene.
template <class Check>
std::array<double, 2> brightness_over_exact(const std::string& json, Check&& check) {
    test::TempDir dir;
    const std::string path = (dir.path() / "scene.json").string();
    std::ofstream(path) << json;
    const Scene s = load_scene(path);
    RenderOptions gt;
    gt.spp = 64;
    const double exact = mean_brightness(render_exact(TracedScene(s), gt).display);
    EXPECT_GT(exact, 2.0);
    const TableCache cache(dir.path().string());
    TableSpec spec;
    spec.encoding = "coverage";
    std::array<double, 2> ratio{};
    for (const LatticeFilter f : {LatticeFilter::kBox, LatticeFilter::kSmooth}) {
        const SceneLattices l = scene_lattices(s, cache, spec, false, {f, false, 0});
        const TracedScene rs(s, [&](int p) { return l.shapes[static_cast<std::size_t>(p)]; });
        ratio[f == LatticeFilter::kBox ? 0 : 1] =
            mean_brightness(render_layered(rs, RenderOptions{}).display) / exact;
        check(rs);
    }
    return ratio;
}

TEST(Coverage, AThinPrimitiveHasTheRightBrightness) {
    const auto ratio = brightness_over_exact(kThinHair, [](const TracedScene& rs) {
        // Partial hits composited in ray order: the same bytes on one thread.
        Image8 one;
        tbb::task_arena(1).execute([&] { one = render_layered(rs, RenderOptions{}).display; });
        EXPECT_EQ(one.rgb, render_layered(rs, RenderOptions{}).display.rgb);
    });
    EXPECT_NEAR(ratio[0], 1.0, 0.02) << "box filter";
    EXPECT_NEAR(ratio[1], 1.0, 0.02) << "smooth filter";
}

// A bead in a 2 x 2 x 2 lattice over a floor, once, or with copies turned about its centre
// (the same solid), which a ray meets in the same place: with sub-rays along the world's
// directions, the copies' partial crossings block the same sub-rays, and the image is the
// single bead's, silhouettes and the floor's soft shadow included. (Offsets along each copy's
// own axes, or coverages composed as independent, made the edges and the shadow darker.) The
// bead is lit by the ambient term alone: the copies, other objects in the same place, would
// shadow each other as coincident objects do in exact mode.
constexpr const char* kTurnedCopies = R"({
  "camera": {"eye": [4, -6, 3.5], "look_at": [1, 1, 1], "up": [0, 0, 1], "fov_y_deg": 22,
             "width": 40, "height": 40},
  "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": true,
  "lights": [{"position": [2, -1, 9], "intensity": [1, 1, 1]}],
  "materials": {"w": {"color": [1, 1, 1], "ka": 0.5, "kd": 0, "ks": 0, "shininess": 1},
                "floor": {"color": [0.8, 0.8, 0.8], "ka": 0.2, "kd": 0.8, "ks": 0, "shininess": 1}},
  "primitives": {"bead": {"spheres": [[1, 1, 1, 0.45]], "cylinders": [],
                          "lattice": {"sigma": 1, "cells": [2, 2, 2]}}},
  "objects": [{"type": "halfspace", "point": [0, 0, 0.3], "normal": [0, 0, 1], "material": "floor"},
              {"type": "instance", "primitive": "bead", "material": "w"}COPIES]
})";

// The scene `text` in lattice mode, the default filter, answered by sub-rays.
Image8 render_filtered(const std::string& text) {
    test::TempDir dir;
    const std::string path = (dir.path() / "copies.json").string();
    std::ofstream(path) << text;
    const Scene s = load_scene(path);
    const TableCache cache(dir.path().string());
    TableSpec spec;
    spec.encoding = "coverage";
    const double spread = 2 * std::tan(22 * M_PI / 360.0) / 40;
    const SceneLattices l = scene_lattices(s, cache, spec, false, {LatticeFilter::kSmooth, true, spread});
    const TracedScene rs(s, [&](int p) { return l.shapes[static_cast<std::size_t>(p)]; });
    const RenderOptions opt;
    const Image8 image = render_layered(rs, opt).display;
    // The same bytes on one thread (the directions across are per ray, not per thread).
    Image8 one;
    tbb::task_arena(1).execute([&] { one = render_layered(rs, opt).display; });
    EXPECT_EQ(one.rgb, image.rgb);
    return image;
}

Image8 render_turned_copies(const std::string& copies) {
    std::string text = kTurnedCopies;
    text.replace(text.find("COPIES"), 6, copies);
    return render_filtered(text);
}

// A bead turned about its centre is the same solid, and shades the same in Phong light with
// shadows: its sheets' sub-rays' own normals are turned into the world with it (SubRayNormals).
TEST(Coverage, ATurnedBeadShadesAsTheBead) {
    std::string text = kTurnedCopies;
    text.replace(text.find("COPIES"), 6, "");
    const std::string matte = R"("ka": 0.5, "kd": 0, "ks": 0, "shininess": 1)";
    text.replace(text.find(matte), matte.size(),
                 R"("ka": 0.1, "kd": 0.6, "ks": 0.5, "shininess": 12)");
    const Image8 plain = render_filtered(text);
    const std::string instance = R"("primitive": "bead", "material": "w")";
    text.replace(
        text.find(instance), instance.size(),
        instance +
            R"(, "transform": [{"translate": [-1, -1, -1]},)"
            R"( {"rotate": {"axis": [1, 2, 3], "angle_deg": 70}}, {"translate": [1, 1, 1]}])");
    const Image8 turned = render_filtered(text);
    ASSERT_EQ(plain.rgb.size(), turned.rgb.size());
    int off = 0, lit = 0;
    for (std::size_t i = 0; i < plain.rgb.size(); ++i) {
        off += std::abs(int(plain.rgb[i]) - int(turned.rgb[i])) > 1;
        lit += plain.rgb[i] > 60;
    }
    EXPECT_EQ(off, 0);
    EXPECT_GT(lit, 100);
}

TEST(Coverage, TurnedCopiesOfABeadRenderAsOne) {
    const Image8 one = render_turned_copies("");
    const std::string turned =
        R"(, {"type": "instance", "primitive": "bead", "material": "w", "transform": [)"
        R"({"translate": [-1, -1, -1]}, {"rotate": {"axis": [AXIS], "angle_deg": ANGLE}},)"
        R"( {"translate": [1, 1, 1]}]})";
    std::string copies;
    for (const auto& [axis, angle] : {std::pair{"0, 0, 1", "90"}, {"1, 2, 3", "70"}, {"3, -1, 1", "200"}}) {
        std::string c = turned;
        c.replace(c.find("AXIS"), 4, axis);
        c.replace(c.find("ANGLE"), 5, angle);
        copies += c;
    }
    const Image8 many = render_turned_copies(copies);
    ASSERT_EQ(one.rgb.size(), many.rgb.size());
    int partial = 0, off = 0;
    for (std::size_t i = 0; i < one.rgb.size(); ++i) {
        off += std::abs(int(one.rgb[i]) - int(many.rgb[i])) > 1;
        partial += one.rgb[i] > 5 && one.rgb[i] < 100;  // a bead's edge against the black sky
    }
    EXPECT_EQ(off, 0);
    EXPECT_GT(partial, 10);
}

// Hairs of radius 0.15 in cells of 1 seen from afar, a pixel about as wide as a cell (what
// the levels of detail choose), lit from the eye: a hair's pairs cover its whole width, whose
// normals' mean is about pi/4 long. Shaded as a unit normal, the diffuse light was a fifth
// too bright (ratio 1.20 and 1.21); the pairs' spread (CoverageSample::spread) brings it to
// within 3 % of the exact mean.
// layers: rows of hairs one behind the other, each 4 units farther and shifted by a quarter
// of the spacing, so that the rows behind show between those in front.
std::string thin_hairs_lit_from_the_eye(int layers = 1, bool shadows = false) {
    std::string objects;
    for (int k = 0; k < layers; ++k)
        for (int i = 0; i < 10; ++i)
            for (int j = 0; j < 8; ++j)
                objects += std::string(objects.empty() ? "" : ",") +
                           R"({"type": "instance", "primitive": "thin", "material": "w", "transform": [)" +
                           R"({"rotate": {"axis": [0, 1, 0], "angle_deg": )" +
                           std::to_string(7 * i + 11 * j + 5 * k) + R"(}}, {"translate": [)" +
                           std::to_string(9 * i - 45 + 2.25 * k) + ", " + std::to_string(4 * k) +
                           ", " + std::to_string(10 * j - 40 + 2.5 * k) + "]}]}";
    return R"({
  "camera": {"eye": [0, -3000, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_y_deg": 2.2, "width": 96, "height": 96},
  "background": [0, 0, 0], "ambient": [0, 0, 0], "shadows": )" +
           std::string(shadows ? "true" : "false") + R"(,
  "lights": [{"position": [0, -3000, 0], "intensity": [1, 1, 1]}],
  "materials": {"w": {"color": [1, 1, 1], "ka": 0, "kd": 1, "ks": 0, "shininess": 1}},
  "primitives": {"thin": {"spheres": [[1.5, 1.3, 1.5, 0.15], [4.5, 1.3, 3.2, 0.15], [1.5, 1.3, 6.5, 0.15]],
                          "cylinders": [[0, 1, 0.15], [1, 2, 0.15]],
                          "lattice": {"sigma": 1, "cells": [6, 3, 8]}}},
  "objects": [)" + objects + "]}";
}

TEST(Coverage, ThinHairsHaveTheRightDiffuseLight) {
    const auto ratio = brightness_over_exact(thin_hairs_lit_from_the_eye(), [](const TracedScene&) {});
    EXPECT_NEAR(ratio[0], 1.0, 0.06) << "box filter";
    EXPECT_NEAR(ratio[1], 1.0, 0.06) << "smooth filter";
}

// Rows of thin hairs behind one another, lit from the eye: every shadow ray retraces its
// camera line, so nothing casts a shadow that can be seen, and shadows must not darken the
// image. A footprint-wide answer finds the rows in front near a shadow ray's start, beside
// the lines that reached the row behind; counted whole (without RayFootprint::seen_until)
// they darkened the image by 2.6 % (box filter) and 2.8 % (smooth).
TEST(Coverage, NoShadowIsSeenFromTheLight) {
    const auto lit = brightness_over_exact(thin_hairs_lit_from_the_eye(4, false), [](const TracedScene&) {});
    const auto shadowed = brightness_over_exact(thin_hairs_lit_from_the_eye(4, true), [](const TracedScene&) {});
    for (std::size_t f = 0; f < 2; ++f) {
        EXPECT_NEAR(shadowed[f] / lit[f], 1.0, 0.01) << (f == 0 ? "box filter" : "smooth filter");
        EXPECT_NEAR(shadowed[f], 1.0, 0.06) << (f == 0 ? "box filter" : "smooth filter");
    }
}

// The same rows answered by their own crossings of sub-rays (footprint filtering), whose shadow
// rays' sub-rays count only past that stretch: without it, shadows darkened the image by 1.7 %.
TEST(Coverage, NoShadowIsSeenFromTheLightBySubRays) {
    auto brightness = [](bool shadows) {
        const Scene s = load_scene_text(thin_hairs_lit_from_the_eye(4, shadows), "rows.json");
        LatticeFiltering f;
        f.filter = LatticeFilter::kSmooth;
        f.lod = true;
        f.policy = LatticePolicy::kFootprint;
        f.spread = PinholeCamera(s.camera).spread();
        const SceneLattices l = scene_lattices(s, nullptr, TableSpec{}, false, f);
        const TracedScene rs(s, [&](int p) { return l.shapes[static_cast<std::size_t>(p)]; });
        return mean_brightness(render_layered(rs, RenderOptions{}).display);
    };
    const double lit = brightness(false);
    EXPECT_GT(lit, 2.0);
    EXPECT_NEAR(brightness(true) / lit, 1.0, 0.01);
}

}  // namespace
}  // namespace lat
