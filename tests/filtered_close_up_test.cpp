// The primitive as the level after the finest table (issue 10): with levels of detail, a ray's
// sheet blends the primitive's own crossings with the tables' answer (exact_weight).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "csg/csg_shape.h"
#include "geometry/chain.h"
#include "geometry/triangle_mesh.h"
#include "hook_primitive.h"
#include "lattice/encoding.h"
#include "lattice/filtered_shape.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

using test::hook;
const TableContext& kFine = test::kHookContext;  // cells of 0.5
const TableContext kCoarse{{4, 2, 4}, 1.0, 1.0, &hook()};

// The hook's coverage tables behind the smooth filter, with and without exact close-ups: one
// level (kFine), or two (kCoarse, then kFine).
struct HookLattice {
    std::vector<ByteBuffer> payloads;  // the tables read them in place
    std::unique_ptr<FilteredLatticeShape> blended, tables_only;
};

// The hook with a fifth bead: 9 parts, enough for the blend to find the parts near a ray
// first (PartBoxes::near_parts), in the hook's box.
const ChainShape& long_hook() {
    static const ChainShape s(
        {{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}, {{2.2, 1, 1.2}, 0.4}},
        {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}, {3, 4, 0.4}});
    return s;
}

HookLattice hook_lattice(bool two_levels, const Shape& primitive = hook()) {
    const Encoding& e = find_encoding("coverage");
    HookLattice h;
    std::vector<FilterLevel> levels;
    std::vector<TableContext> contexts{kFine};
    if (two_levels) contexts.insert(contexts.begin(), kCoarse);
    for (TableContext& ctx : contexts) ctx.primitive = &primitive;
    h.payloads.reserve(contexts.size());
    for (const TableContext& ctx : contexts) {
        const RasterizeResult r = rasterize(ctx);
        h.payloads.push_back(e.build(r.raw, ctx, {}));
        levels.push_back({e.open(h.payloads.back().data(), h.payloads.back().size(), r.hits, ctx), ctx});
    }
    const double error = e.error_bound(kFine, {});
    h.blended = std::make_unique<FilteredLatticeShape>(levels, LatticeFilter::kSmooth, error, true);
    h.tables_only = std::make_unique<FilteredLatticeShape>(levels, LatticeFilter::kSmooth, error, false);
    return h;
}

// The footprint width (unit directions, no spread) whose level lies `past` levels beyond the
// finest one's (lod_level counts from the coarsest, cell0).
double width_past(double past, bool two_levels) {
    const double cell0 = two_levels ? kCoarse.cell : kFine.cell;
    const double top = two_levels ? 1 : 0;
    return cell0 / (kCellPerFootprint * std::exp2(top + past));
}

// Rays through the hook's box: lines from outside it, or rays starting inside it.
std::vector<Ray> rays(int n, bool inside = false) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Bounds3 box{{0, 0, 0}, Vec3{4, 2, 4}};
    const Bounds3 around = expand(box, 0.5);
    auto point = [&](const Bounds3& b) { return b.lo + Vec3{u(rng), u(rng), u(rng)} * (b.hi - b.lo); };
    std::vector<Ray> out;
    for (int i = 0; i < n; ++i) {
        const Vec3 p = point(inside ? box : around), q = point(around);
        out.push_back({inside ? p : p - (q - p) * 4.0, (q - p) / length(q - p)});
    }
    return out;
}

// Shadow rays (coverage only) far past the finest level get the primitive's crossing itself,
// from outside the box or from inside it, after tmin; occluded() says whether there is one.
TEST(FilteredCloseUps, ShadowRaysFarPastTheFinestLevelGetThePrimitivesCrossing) {
    for (const bool two : {false, true}) {
        const HookLattice h = hook_lattice(two);
        set_ray_footprint({width_past(kShadowExact.to + 0.5, two), 0, true});
        int hits = 0;
        for (const bool inside : {false, true})
            for (const Ray& r : rays(3000, inside)) {
                const double tmin = inside ? 0.3 : 0.0;
                Crossing exact, got;
                const bool e = hook().intersect(r, tmin, kInfinity, exact);
                ASSERT_EQ(h.blended->intersect(r, tmin, kInfinity, got), e);
                EXPECT_EQ(h.blended->occluded(r, tmin, 20.0), e && exact.t < 20.0);
                if (!e) continue;
                ++hits;
                EXPECT_NEAR(got.t, exact.t, 1e-9);
                EXPECT_EQ(got.coverage, 1.0f);
            }
        EXPECT_GT(hits, 1000);
    }
    set_ray_footprint({});
}

// Camera rays: a vanishing footprint puts all their sub-rays on the ray, so the sheet is the
// crossing and its normal; a footprint a few cells wide covers the hook's edges in part, in
// steps of one sub-ray. The tables alone answer otherwise.
TEST(FilteredCloseUps, CameraRaysFarPastTheFinestLevelGetTheirSubRaysCrossings) {
    const HookLattice h = hook_lattice(false);
    set_ray_footprint({1e-9, 0, false});
    int hits = 0, tables_differ = 0;
    for (const Ray& r : rays(5000)) {
        Crossing exact, got, table;
        const bool e = hook().intersect(r, 0.0, kInfinity, exact);
        ASSERT_EQ(h.blended->intersect(r, 0.0, kInfinity, got), e);
        if (!e) continue;
        ++hits;
        EXPECT_NEAR(got.t, exact.t, 1e-6);
        EXPECT_EQ(got.coverage, 1.0f);
        EXPECT_NEAR(length(got.stored.n - normalize(hook().normal(r, exact))), 0.0, 1e-6);
        tables_differ += !h.tables_only->intersect(r, 0.0, kInfinity, table) ||
                         std::abs(table.t - exact.t) > 1e-6;
    }
    EXPECT_GT(hits, 500);
    EXPECT_GT(tables_differ, hits / 2);  // the test can tell the tables from the primitive

    set_ray_footprint({width_past(kCameraExact.to + 0.1, false), 0, false});
    const int n = kCameraExact.sub_rays * kCameraExact.sub_rays;
    int partial = 0;
    for (const Ray& r : rays(20000)) {
        Crossing got;
        if (!h.blended->intersect(r, 0.0, kInfinity, got)) continue;
        const double k = double(got.coverage) * n;
        EXPECT_NEAR(k, std::round(k), 1e-5);
        partial += got.coverage < 1.0f;
    }
    EXPECT_GT(partial, 20);
    set_ray_footprint({});
}

TEST(FilteredCloseUps, TheRampBlendsTheTablesSheetWithTheCrossing) {
    const HookLattice h = hook_lattice(false);
    const double past = 0.5 * (kShadowExact.from + kShadowExact.to);
    ASSERT_EQ(exact_weight(past, kShadowExact), 0.5);
    set_ray_footprint({width_past(past, false), 0, true});
    int blended = 0;
    for (const Ray& r : rays(5000)) {
        Crossing exact, got, table;
        const double e = hook().intersect(r, 0.0, kInfinity, exact) ? 1.0 : 0.0;
        const double a = h.tables_only->intersect(r, 0.0, kInfinity, table) ? double(table.coverage) : 0.0;
        const double want = 0.5 * a + 0.5 * e;
        const bool hit = h.blended->intersect(r, 0.0, kInfinity, got);
        if (want > 0 && want < 1) ++blended;
        if (!hit) {
            EXPECT_LT(want, 1e-6);
            continue;
        }
        EXPECT_NEAR(got.coverage, want >= 1 - 1e-6 ? 1.0 : want, 1e-6);
        // The sheet's point is the blend of both: between them along the ray.
        if (a > 0 && e > 0) {
            EXPECT_LE(got.t, std::max(table.t, exact.t) + 1e-9);
            EXPECT_GE(got.t, std::min(table.t, exact.t) - 1e-9);
        }
    }
    set_ray_footprint({});
    EXPECT_GT(blended, 200);
}

// Camera rays at the finest level: half the tables' sheet, half the crossings of their sub-rays
// (a grid across the footprint, recomputed here), in coverage and in the normal.
// (With the hook, and with a hook of 9 parts, whose sub-rays meet only the parts found near
// the ray first: the same crossings as the whole primitive's.)
void expect_camera_rays_blend_half_their_sub_rays(const ChainShape& prim) {
    const HookLattice h = hook_lattice(false, prim);
    ASSERT_EQ(exact_weight(0.0, kCameraExact), 0.5);
    const double width = width_past(0.0, false);
    set_ray_footprint({width, 0, false});
    const int n = kCameraExact.sub_rays;
    const Bounds3 box{{0, 0, 0}, Vec3{4, 2, 4}};
    int checked = 0;
    for (const Ray& r : rays(3000)) {
        Crossing table, got;
        const bool ht = h.tables_only->intersect(r, 0.0, kInfinity, table);
        double alpha = ht ? 0.5 * double(table.coverage) : 0.0;
        Vec3 normal = ht ? table.stored.n * (0.5 * double(table.coverage)) : Vec3{};
        Vec3 u, v;
        orthonormal_basis(r.d, u, v);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const Ray sub{r.o + u * (((i + 0.5) / n - 0.5) * width) + v * (((j + 0.5) / n - 0.5) * width), r.d};
                double t0 = 0, t1 = kInfinity;
                Crossing c;
                if (!clip_ray(box, sub, t0, t1) || !prim.intersect(sub, t0, t1, c)) continue;
                alpha += 0.5 / (n * n);
                normal += normalize(prim.normal(sub, c)) * (0.5 / (n * n));
            }
        const bool hit = h.blended->intersect(r, 0.0, kInfinity, got);
        if (alpha <= 1e-6) {
            EXPECT_FALSE(hit);
            continue;
        }
        ASSERT_TRUE(hit);
        ++checked;
        EXPECT_NEAR(got.coverage, alpha >= 1 - 1e-6 ? 1.0 : alpha, 1e-6);
        EXPECT_NEAR(length(got.stored.n - normal / alpha), 0.0, 1e-6);
    }
    set_ray_footprint({});
    EXPECT_GT(checked, 500);
}

TEST(FilteredCloseUps, CameraRaysBlendHalfTheirSubRaysCrossings) {
    ASSERT_LT(hook().primitive_count(), 8u);
    expect_camera_rays_blend_half_their_sub_rays(hook());
    ASSERT_GE(long_hook().primitive_count(), 8u);
    expect_camera_rays_blend_half_their_sub_rays(long_hook());
}

// A ray's direction need not be a unit vector in the primitive's frame (scaled instances): the
// footprint scales with it, so twice the direction and half the footprint is the same ray and
// footprint, answered at half the parameter.
TEST(FilteredCloseUps, LongerDirectionsAreTheSameRay) {
    const HookLattice h = hook_lattice(false);
    for (const double past : {0.0, 1.0, kCameraExact.to + 0.5}) {
        const double width = width_past(past, false);
        for (const bool shadow : {false, true}) {
            int hits = 0;
            for (const Ray& r : rays(2000)) {
                Crossing a, b;
                set_ray_footprint({width, 0, shadow});
                const bool ha = h.blended->intersect(r, 0.0, kInfinity, a);
                set_ray_footprint({width / 2, 0, shadow});
                const bool hb = h.blended->intersect({r.o, r.d * 2.0}, 0.0, kInfinity, b);
                ASSERT_EQ(ha, hb) << "past " << past;
                if (!ha) continue;
                ++hits;
                EXPECT_NEAR(b.t, a.t / 2, 1e-9);
                EXPECT_NEAR(b.coverage, a.coverage, 1e-6);
                EXPECT_NEAR(length(b.stored.n - a.stored.n), 0.0, 1e-9);
            }
            EXPECT_GT(hits, 300);
        }
    }
    set_ray_footprint({});
}

// How far a ray may go (tmax: for camera rays in the accelerator, the closest crossing found
// so far) only cuts the sheet, as for the tables: the answer is the same whatever order the
// accelerator meets objects in.
TEST(FilteredCloseUps, TheSheetIsCutAtTmaxNotMadeOfWhatLiesBeforeIt) {
    const HookLattice h = hook_lattice(false);
    for (const double past : {0.0, kCameraExact.to + 0.5}) {
        set_ray_footprint({width_past(past, false), 0, false});
        for (const Ray& r : rays(3000)) {
            Crossing whole, cut;
            if (!h.blended->intersect(r, 0.0, kInfinity, whole)) continue;
            for (const double tmax : {whole.t - 0.01, whole.t + 0.01}) {
                const bool hit = h.blended->intersect(r, 0.0, tmax, cut);
                ASSERT_EQ(hit, whole.t < tmax);
                if (!hit) continue;
                EXPECT_EQ(cut.t, whole.t);
                EXPECT_EQ(cut.coverage, whole.coverage);
            }
        }
    }
    set_ray_footprint({});
}

// Shadow rays short of their ramp, and rays without a footprint (width 0 asks for the finest
// level), read the tables alone: the same answers, to the bit, as without the blend. With two
// levels, "past" counts from the finest one.
TEST(FilteredCloseUps, FootprintsShortOfTheRampReadTheTablesAlone) {
    struct Case {
        bool shadow;
        double past;  // NaN: no footprint
    };
    const double none = std::nan("");
    const std::vector<Case> cases{{false, none},
                                  {true, none},
                                  {true, kShadowExact.from - 0.01},
                                  {true, 0.0}};
    for (const bool two : {false, true}) {
        const HookLattice h = hook_lattice(two);
        for (const Case& c : cases) {
            const double width = std::isnan(c.past) ? 0.0 : width_past(c.past, two);
            set_ray_footprint({width, 0, c.shadow});
            for (const Ray& r : rays(2000)) {
                Crossing a, b;
                const bool ha = h.blended->intersect(r, 0.0, kInfinity, a);
                ASSERT_EQ(ha, h.tables_only->intersect(r, 0.0, kInfinity, b))
                    << "past " << c.past << (c.shadow ? ", shadow ray" : ", camera ray");
                if (!ha) continue;
                EXPECT_EQ(a.t, b.t);
                EXPECT_EQ(a.coverage, b.coverage);
                EXPECT_EQ(a.stored.n.x, b.stored.n.x);
                EXPECT_EQ(a.stored.n.y, b.stored.n.y);
                EXPECT_EQ(a.stored.n.z, b.stored.n.z);
            }
        }
    }
    set_ray_footprint({});
}

// How many of 3000 rays far past the finest level a primitive in a {4, 2, 4} box answers
// differently with the exact blend asked for than without it.
int differing_answers(const Shape& primitive) {
    const TableContext ctx{{4, 2, 4}, 1.0, 1.0, &primitive};
    const Encoding& e = find_encoding("coverage");
    const RasterizeResult raster = rasterize(ctx);
    const ByteBuffer payload = e.build(raster.raw, ctx, {});
    const std::vector<FilterLevel> levels{
        {e.open(payload.data(), payload.size(), raster.hits, ctx), ctx}};
    const FilteredLatticeShape asked(levels, LatticeFilter::kSmooth, e.error_bound(ctx, {}), true);
    const FilteredLatticeShape tables(levels, LatticeFilter::kSmooth, e.error_bound(ctx, {}), false);
    set_ray_footprint({1e-9, 0, false});  // far past the finest level
    int differ = 0;
    for (const Ray& r : rays(3000)) {
        Crossing a, b;
        const bool ha = asked.intersect(r, 0.0, kInfinity, a), hb = tables.intersect(r, 0.0, kInfinity, b);
        differ += ha != hb || (ha && (a.t != b.t || a.coverage != b.coverage));
    }
    set_ray_footprint({});
    return differ;
}

// A row of `parts` beads across the box.
ChainShape beads(std::size_t parts) {
    std::vector<ChainSphere> b;
    for (std::size_t i = 0; i < parts; ++i)
        b.push_back({{0.5 + 3.0 * double(i) / double(parts - 1), 1.0, 2.0}, 0.2});
    return ChainShape(b, {});
}

// A primitive whose exact intersection costs more than kMaxExactCost simple tests keeps to its
// tables: a chain would test every part, for every sub-ray.
TEST(FilteredCloseUps, PrimitivesOfManyPartsKeepToTheirTables) {
    const auto most = static_cast<std::size_t>(kMaxExactCost);
    EXPECT_EQ(differing_answers(beads(most + 1)), 0);
    EXPECT_GT(differing_answers(beads(most)), 500);  // the blend shows where it is allowed
}

// A mesh descends its own hierarchy: one of many more triangles than kMaxExactCost is blended
// (a sheet of 2 x 12 x 8 triangles); and a CSG tree costs its leaves' costs, so one with such
// a chain as a leaf keeps to its tables.
TEST(FilteredCloseUps, MeshesAreBlendedAndTreesCostTheirLeaves) {
    std::vector<Vec3> positions;
    std::vector<TriangleMeshShape::Triangle> triangles;
    const int nu = 12, nv = 8;
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i)
            positions.push_back({0.5 + 3.0 * i / nu, 0.6 + 0.8 * j / nv, 1.0 + 2.0 * j / nv});
    const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (nu + 1) + i); };
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    const TriangleMeshShape sheet(positions, triangles);
    ASSERT_GT(static_cast<double>(sheet.primitive_count()), kMaxExactCost);
    EXPECT_LE(sheet.intersect_cost(), kMaxExactCost);
    EXPECT_GT(differing_answers(sheet), 500);

    CsgShape tree;
    const auto small = static_cast<std::size_t>(kMaxExactCost) / 2;
    const int a = tree.add_leaf({std::make_shared<ChainShape>(beads(small)), {}, 1});
    const int b = tree.add_leaf({std::make_shared<ChainShape>(beads(small + 1)), {}, 2});
    tree.set_root(tree.add_node(CsgOp::kUnion, {a, b}));
    EXPECT_EQ(tree.intersect_cost(), double(2 * small + 1));
    EXPECT_EQ(differing_answers(tree), 0);
}

}  // namespace
}  // namespace lat
