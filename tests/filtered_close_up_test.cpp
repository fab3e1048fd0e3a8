// Filtered lattices answered from the primitive's own crossings: with levels of
// detail, a primitive cheap to intersect answers each ray with the crossings of sub-rays
// across its footprint (answered_by_primitive), not with its tables.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <random>

#include "accel/embree_accel.h"
#include "csg/csg_shape.h"
#include "geometry/chain.h"
#include "geometry/lattice_source.h"
#include "geometry/named_shapes.h"
#include "geometry/sphere.h"
#include "coverage/sheets.h"
#include "coverage/sub_rays.h"
#include "geometry/triangle_mesh.h"
#include "hook_primitive.h"
#include "lattice/encoding.h"
#include "lattice/answer_plan.h"
#include "lattice/filtered_shape.h"
#include "lattice/sub_ray_shape.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

using test::hook;
const TableContext& kFine = test::kHookContext;  // cells of 0.5

// The hook's coverage table (kFine) behind the smooth filter, answered from the primitive's own
// crossings or by the table alone.
struct HookLattice {
    std::vector<ByteBuffer> payloads;  // the tables read them in place
    std::unique_ptr<SubRayShape> exact;
    std::unique_ptr<FilteredLatticeShape> tables_only;
};

// The widest footprint the exact hook's sub-rays span (kFine cells of 0.5).
constexpr double kExactWidth = 3.0;

// The hook with a fifth bead: 9 parts, enough for the sub-rays to find the parts near a ray
// first (PartBoxes::near_parts), in the hook's box.
const ChainShape& long_hook() {
    static const ChainShape s(
        {{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}, {{2.2, 1, 1.2}, 0.4}},
        {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}, {3, 4, 0.4}});
    return s;
}

HookLattice hook_lattice(const Shape& primitive = hook()) {
    const Encoding& e = find_encoding("coverage");
    TableContext ctx = kFine;
    ctx.primitive = &primitive;
    HookLattice h;
    const RasterizeResult r = rasterize(ctx);
    h.payloads.push_back(e.build(r.raw, ctx, {}));
    const std::vector<FilterLevel> levels{
        {e.open(h.payloads.back().data(), h.payloads.back().size(), r.hits, ctx), ctx}};
    const double error = e.error_bound(kFine, {});
    h.exact = std::make_unique<SubRayShape>(ctx, levels.back().table, error, kExactWidth);
    h.tables_only = std::make_unique<FilteredLatticeShape>(levels, LatticeFilter::kSmooth, error);
    return h;
}

// A footprint of this width, spread and purpose, without directions across the ray or a bound:
// what a shape tested outside a traversal is given.
RayFootprint width_footprint(double width0, double spread = 0, bool coverage_only = false) {
    RayFootprint f;
    f.width0 = width0;
    f.spread = spread;
    f.coverage_only = coverage_only;
    return f;
}
// r with footprint f.
Ray with(const Ray& r, const RayFootprint& f) {
    return {r.o, r.d, &f};
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

// Shadow rays (coverage only) of a vanishing footprint are blocked (coverage 1) exactly where
// the primitive crosses them between tmin and tmax, from outside the box or from inside it,
// with the sheet in that range; occluded() says the same.
TEST(FilteredCloseUps, ShadowRaysAreBlockedWhereThePrimitiveCrossesThem) {
    const HookLattice h = hook_lattice();
    for (const double footprint : {1e-9, 0.0}) {
        const RayFootprint f = width_footprint(footprint, 0, true);
        int hits = 0;
        for (const bool inside : {false, true})
            for (const Ray& r : rays(3000, inside)) {
                const double tmin = inside ? 0.3 : 0.0;
                Crossing exact;
                const bool e = hook().intersect(r, tmin, kInfinity, exact);
                for (const double tmax : {kInfinity, e ? exact.t + 0.01 : 20.0, e ? exact.t - 0.01 : 5.0}) {
                    const bool want = e && exact.t < tmax;
                    Crossing got;
                    ASSERT_EQ(h.exact->intersect(with(r, f), tmin, tmax, got), want);
                    EXPECT_EQ(h.exact->occluded(with(r, f), tmin, tmax), want);
                    if (!want) continue;
                    ++hits;
                    EXPECT_EQ(got.coverage, 1.0f);
                    EXPECT_GT(got.t, tmin);
                    EXPECT_LT(got.t, tmax);
                }
            }
        EXPECT_GT(hits, 2000);
    }
}

// Camera rays: a vanishing footprint puts all their sub-rays on the ray, so the sheet is the
// crossing and its normal; a footprint a few cells wide covers the hook's edges in part, in
// steps of one sub-ray.
TEST(FilteredCloseUps, CameraRaysGetTheirSubRaysCrossings) {
    const HookLattice h = hook_lattice();
    const RayFootprint vanishing = width_footprint(1e-9);
    int hits = 0, tables_differ = 0;
    for (const Ray& r : rays(5000)) {
        Crossing exact, got, table;
        const bool e = hook().intersect(r, 0.0, kInfinity, exact);
        ASSERT_EQ(h.exact->intersect(with(r, vanishing), 0.0, kInfinity, got), e);
        if (!e) continue;
        ++hits;
        EXPECT_NEAR(got.t, exact.t, 1e-6);
        EXPECT_EQ(got.coverage, 1.0f);
        EXPECT_NEAR(length(got.stored.n - normalize(hook().normal(r, exact))), 0.0, 1e-6);
        tables_differ += !h.tables_only->intersect(with(r, vanishing), 0.0, kInfinity, table) ||
                         std::abs(table.t - exact.t) > 1e-6;
    }
    EXPECT_GT(hits, 500);
    EXPECT_GT(tables_differ, hits / 2);  // the test can tell the tables from the primitive

    const RayFootprint wide = width_footprint(1.0);
    const int n = kExactSubRays * kExactSubRays;
    int partial = 0;
    for (const Ray& r : rays(20000)) {
        Crossing got;
        if (!h.exact->intersect(with(r, wide), 0.0, kInfinity, got)) continue;
        const double k = double(got.coverage) * n;
        EXPECT_NEAR(k, std::round(k), 1e-5);
        partial += got.coverage < 1.0f;
    }
    EXPECT_GT(partial, 20);
}

// A ray's sheet is the crossings of its sub-rays (a grid across the footprint, recomputed
// here): a camera ray's, their share as the coverage, the mean of their points and unit
// normals as the sheet's; a shadow ray's, the share of them blocked before tmax (here the
// middle of the box along the ray). Footprints wider than the shape's exact width are narrowed
// to it. (With the hook, and with a hook of 9 parts, whose sub-rays meet only the parts found
// near the ray first: the same crossings as the whole primitive's.) A primitive costlier than
// kMaxExactCost (not a chain) blocks a shadow ray's sub-rays in pairs, the rows {0, 1} and
// {3, 2} of lanes k = i n + j: a pair's live lanes are blocked when its first live one is.
void expect_sheets_are_their_sub_rays_crossings(const Shape& prim, bool shadow,
                                                 int least_checked) {
    const bool paired = shadow && ShapeSource(prim).intersect_cost() > kMaxExactCost;
    const HookLattice h = hook_lattice(prim);
    const int n = kExactSubRays;
    const Bounds3 box{{0, 0, 0}, Vec3{4, 2, 4}};
    int checked = 0;
    for (const double footprint : {0.4, 1.0, 2 * kExactWidth}) {
        const double width = std::min(footprint, kExactWidth);
        const RayFootprint f = width_footprint(footprint, 0, shadow);
        for (const Ray& r : rays(2000)) {
            const double tmax = shadow ? dot(box.center() - r.o, r.d) : kInfinity;
            double alpha = 0;
            Vec3 normal, point;
            Vec3 u, v;
            orthonormal_basis(r.d, u, v);
            bool live[4] = {}, met[4] = {};
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const Vec3 offset = u * (((i + 0.5) / n - 0.5) * width) + v * (((j + 0.5) / n - 0.5) * width);
                    const Ray sub{r.o + offset, r.d};
                    double t0 = 0, t1 = kInfinity;
                    Crossing c;
                    live[i * n + j] = clip_ray(box, sub, t0, t1) && t0 < std::min(t1, tmax);
                    if (!live[i * n + j] || !prim.intersect(sub, t0, t1, c) || c.t >= tmax)
                        continue;
                    met[i * n + j] = true;
                    alpha += 1.0 / (n * n);
                    normal += normalize(prim.normal(sub, c)) * (1.0 / (n * n));
                    point += sub.at(c.t) * (1.0 / (n * n));
                }
            if (paired) {
                alpha = 0;
                for (const auto& [a, b] : {std::pair{0, 1}, std::pair{3, 2}})
                    if (live[a] ? met[a] : met[b]) alpha += (live[a] + live[b]) / 4.0;
            }
            Crossing got;
            const bool hit = h.exact->intersect(with(r, f), 0.0, tmax, got);
            ASSERT_EQ(hit, alpha > 0) << "footprint " << footprint;
            if (!hit) continue;
            ++checked;
            EXPECT_NEAR(got.coverage, alpha, 1e-6);
            if (!shadow) {
                EXPECT_NEAR(length(got.stored.p - point / alpha), 0.0, 1e-6);
                EXPECT_NEAR(length(got.stored.n - normal / alpha), 0.0, 1e-6);
            }
        }
    }
    EXPECT_GT(checked, least_checked);
}

// Two tori, one bitten by a ball: a CSG tree cheap enough to answer by its crossings, whose
// normals depend on the leaf a crossing is on and on whether it is a subtracted solid's.
const CsgShape& bitten_tori() {
    static const CsgShape tree = [] {
        CsgShape t;
        const PlacedShape a = make_torus({1.4, 1, 2}, {1, 0.3, 0.5}, 0.9, 0.3);
        const PlacedShape b = make_torus({2.6, 1, 2.2}, {0.2, 1, 0.4}, 0.8, 0.25);
        const int ta = t.add_leaf({a.shape, a.placement, 1});
        const int ball = t.add_leaf({std::make_shared<SphereShape>(Vec3{2.2, 1, 2.1}, 0.45), {}, 2});
        const int tb = t.add_leaf({b.shape, b.placement, 3});
        t.set_root(t.add_node(CsgOp::kUnion, {t.add_node(CsgOp::kDifference, {ta, ball}), tb}));
        return t;
    }();
    return tree;
}

// Six tori: a CSG tree costlier than kMaxExactCost (answered by its crossings only past the
// build budget), whose shadow rays test their sub-rays in pairs.
const CsgShape& six_tori() {
    static const CsgShape tree = [] {
        CsgShape t;
        std::vector<int> leaves;
        for (int i = 0; i < 6; ++i) {
            const PlacedShape torus = make_torus({0.75 + 0.5 * i, 1, 2}, {1, 0.3 * i, 0.5}, 0.5, 0.15);
            leaves.push_back(t.add_leaf({torus.shape, torus.placement, static_cast<std::uint32_t>(i + 1)}));
        }
        t.set_root(t.add_node(CsgOp::kUnion, leaves));
        return t;
    }();
    return tree;
}

TEST(FilteredCloseUps, SheetsAreTheirSubRaysCrossings) {
    ASSERT_LT(hook().part_count(), 8u);
    ASSERT_GE(long_hook().part_count(), 8u);
    ASSERT_LE(bitten_tori().intersect_cost(), kMaxExactCost);
    ASSERT_GT(six_tori().intersect_cost(), kMaxExactCost);
    for (const bool shadow : {false, true}) {
        expect_sheets_are_their_sub_rays_crossings(hook(), shadow, shadow ? 700 : 1500);
        expect_sheets_are_their_sub_rays_crossings(long_hook(), shadow, shadow ? 700 : 1500);
        expect_sheets_are_their_sub_rays_crossings(bitten_tori(), shadow, shadow ? 300 : 600);
        expect_sheets_are_their_sub_rays_crossings(six_tori(), shadow, shadow ? 300 : 600);
    }
}

// A camera ray's sheets (SheetSource) split its sub-rays by depth: the sub-rays that meet the
// primitive within kSheetDepth footprint widths of the nearest make the first sheet, those
// within that of the nearest left the next, each sheet the mean of its sub-rays' points and
// normals and their share as the coverage, with the sub-rays' own normals, in ray order;
// together, intersect's one sheet. With the world's directions across the ray only; without
// them, intersect's sheet (no normals).
TEST(FilteredCloseUps, SheetsSplitTheSubRaysByDepth) {
    const HookLattice h = hook_lattice(long_hook());
    const SubRayShape& s = *h.exact;
    const Bounds3 box{{0, 0, 0}, Vec3{4, 2, 4}};
    const int n = kExactSubRays;
    int split = 0, whole = 0;
    for (const double footprint : {0.4, 1.0, kExactWidth}) {
        // Without the world's directions across the ray.
        const RayFootprint own = width_footprint(footprint);
        for (const Ray& ray : rays(2000)) {
            // unit: the world's directions are r's basis
            const RayFootprint world = footprint_across(ray.d, footprint, 0, false);
            const Ray r = with(ray, world);
            // Each sub-ray's first crossing, as the grid of
            // expect_sheets_are_their_sub_rays_crossings.
            std::array<double, kSubRays> t;
            std::array<Vec3, kSubRays> p, nrm;
            unsigned met = 0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const int k = i * n + j;
                    const Vec3 offset = world.u * (((i + 0.5) / n - 0.5) * footprint) +
                                        world.v * (((j + 0.5) / n - 0.5) * footprint);
                    const Ray sub{r.o + offset, r.d};
                    double t0 = 0, t1 = kInfinity;
                    Crossing c;
                    if (!clip_ray(box, sub, t0, t1) || !long_hook().intersect(sub, t0, t1, c))
                        continue;
                    met |= 1u << k;
                    t[k] = c.t, p[k] = sub.at(c.t), nrm[k] = normalize(long_hook().normal(sub, c));
                }
            std::array<SheetCrossing, kMaxSheets> got;
            const int count = s.sheets(r, 0.0, kInfinity, got);
            int expected = 0;
            for (unsigned left = met; left != 0; ++expected) {
                double nearest = kInfinity;
                for (int k = 0; k < kSubRays; ++k)
                    if (left >> k & 1) nearest = std::min(nearest, t[k]);
                unsigned group = 0;
                Vec3 mean_p, mean_n;
                for (int k = 0; k < kSubRays; ++k)
                    if (left >> k & 1 && t[k] <= nearest + kSheetDepth * footprint)
                        group |= 1u << k, mean_p += p[k], mean_n += nrm[k];
                left &= ~group;
                ASSERT_LT(expected, count) << "footprint " << footprint;
                const Crossing& c = got[static_cast<std::size_t>(expected)].crossing;
                const SubRayNormals& normals = got[static_cast<std::size_t>(expected)].normals;
                ASSERT_EQ(normals.count, std::popcount(group));
                for (int k = 0, i = 0; k < kSubRays; ++k)
                    if (group >> k & 1) {
                        EXPECT_NEAR(length(normals.n[i++] - nrm[k]), 0.0, 1e-6);
                    }
                const double share = double(std::popcount(group)) / kSubRays;
                EXPECT_EQ(c.sub_rays, group);
                EXPECT_NEAR(c.coverage, share, 1e-6);
                EXPECT_NEAR(length(c.stored.p - mean_p / std::popcount(group)), 0.0, 1e-6);
                EXPECT_NEAR(length(c.stored.n - mean_n / std::popcount(group)), 0.0, 1e-6);
                if (expected > 0) {
                    EXPECT_GT(c.t, got[static_cast<std::size_t>(expected - 1)].crossing.t);
                }
            }
            EXPECT_EQ(count, expected);
            // A tmax between two sheets cuts the farther: the nearer are as they were.
            if (count > 1) {
                std::array<SheetCrossing, kMaxSheets> cut;
                const double tmax = 0.5 * (got[0].crossing.t + got[1].crossing.t);
                ASSERT_EQ(s.sheets(r, 0.0, tmax, cut), 1);
                EXPECT_EQ(cut[0].crossing.t, got[0].crossing.t);
                EXPECT_EQ(cut[0].crossing.sub_rays, got[0].crossing.sub_rays);
            }
            split += count > 1;
            whole += count == 1;
            // Together: intersect's one sheet.
            Crossing one;
            ASSERT_EQ(s.intersect(r, 0.0, kInfinity, one), met != 0);
            if (met != 0) {
                EXPECT_EQ(one.sub_rays, met);
            }
            // Without the world's directions: that one sheet.
            if (met != 0) {
                ASSERT_EQ(s.sheets(with(ray, own), 0.0, kInfinity, got), 1);
                EXPECT_NEAR(got[0].crossing.t, one.t, 1e-9);
                EXPECT_EQ(got[0].normals.count, 0);
            }
        }
    }
    EXPECT_GT(split, 200);
    EXPECT_GT(whole, 1000);
}

// Culling reaches as far as each ray's own sub-rays: a ray whose sheet has a crossing meets
// one of the cull parts and the accelerator's boxes, whatever its footprint (none, narrowed to
// the exact width or not; its line through the lattice box or past it); rays clear of the hook
// by more than their sub-rays' reach are culled.
TEST(FilteredCloseUps, CullingReachesAsFarAsTheRaysSubRays) {
    const HookLattice h = hook_lattice(long_hook());
    const SubRayShape& s = *h.exact;
    ASSERT_GT(s.cull_count(), 0u);
    const auto meets_a_part = [&](const Ray& r) {
        for (std::size_t i = 0; i < s.cull_count(); ++i)
            if (s.cull_meets(i, r)) return true;
        return false;
    };
    // The accelerator's boxes: the parts' (their lines start outside them), and the shape's.
    const auto meets_a_box = [&](const Ray& r) {
        double t0 = 0, t1 = kInfinity;
        if (!clip_ray(s.bounds(), r, t0, t1)) return false;
        for (std::size_t i = 0; i < s.cull_count(); ++i)
            if (t0 = 0, t1 = kInfinity; clip_ray(s.cull_bounds(i, Transform{}, kInfinity), r, t0, t1))
                return true;
        return false;
    };
    int hits = 0, culled = 0, outside = 0;
    for (const double footprint : {0.0, 0.05, 0.5, 2.0, kExactWidth, 3 * kExactWidth}) {
        const RayFootprint f = width_footprint(footprint);
        for (const Ray& line : rays(4000)) {
            const Ray r = with(line, f);
            Crossing c;
            if (s.intersect(r, 0.0, kInfinity, c)) {
                ++hits;
                EXPECT_TRUE(meets_a_part(r)) << "footprint " << footprint;
                EXPECT_TRUE(meets_a_box(r)) << "footprint " << footprint;
                double t0 = 0, t1 = kInfinity;
                outside += !clip_ray(Bounds3{{0, 0, 0}, Vec3{4, 2, 4}}, r, t0, t1);
            } else {
                culled += !meets_a_part(r);
            }
        }
    }
    EXPECT_GT(hits, 3000);
    EXPECT_GT(culled, 3000);
    EXPECT_GT(outside, 20);  // rays whose lines miss the lattice box, answered by sub-rays
}

// Rays lying in the planes across each axis through a point: where a cull box split in halves
// (LatticeFrame::split_in_halves) is cut.
std::vector<Ray> rays_in_mid_planes(Vec3 centre, int per_plane) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Ray> out;
    for (std::size_t axis = 0; axis < 3; ++axis)
        for (int i = 0; i < per_plane; ++i) {
            Vec3 p = centre + Vec3{u(rng), u(rng), u(rng)} * 2.5, d{u(rng), u(rng), u(rng)};
            p[axis] = centre[axis];
            d[axis] = 0;
            if (length(d) < 1e-3) continue;
            d = d / length(d);
            out.push_back({p - d * 8.0, d});
        }
    return out;
}

// An instance whose rays span at most `widest` (AccelObject::widest_footprint) is culled by
// its own narrower boxes and capsules, placed in world space: every ray (of any footprint,
// wider ones narrowed to it) whose sheet has a crossing meets one of them and passes cull_meets,
// under a rotation and scale too, including rays in the planes where a box split in halves is
// cut; and narrower instances cull more rays. For a chain (capsules), a ball and a CSG tree
// (boxes, split in halves).
void expect_instances_culled_by_their_own_bound(const Shape& primitive) {
    const HookLattice h = hook_lattice(primitive);
    const SubRayShape& s = *h.exact;
    const Transform turned = Transform::translate({3, -2, 5}) * Transform::rotate({1, 2, 3}, 0.7) *
                             Transform::scale({1.5, 1.5, 1.5});
    std::vector<Ray> local_rays = rays(1500);
    for (const Vec3 centre : {Vec3{2, 1, 2}, primitive.bounds().center()})
        for (const Ray& r : rays_in_mid_planes(centre, 150)) local_rays.push_back(r);
    int last_culled = -1;
    for (const double widest : {kInfinity, 0.7 * kExactWidth, 0.3 * kExactWidth, 0.05}) {
        int hits = 0, culled = 0;
        for (const Transform& xf : {Transform{}, turned}) {
            std::vector<Bounds3> boxes;
            std::vector<FloatCapsule> capsules;
            for (std::size_t i = 0; i < s.cull_count(); ++i) {
                boxes.push_back(s.cull_bounds(i, xf, widest));
                Capsule c;
                capsules.push_back(s.cull_capsule(i, xf, widest, c) ? FloatCapsule::holding(c)
                                                                    : FloatCapsule{});
            }
            const auto kept = [&](const Ray& world, const Ray& local) {
                for (std::size_t i = 0; i < boxes.size(); ++i)
                    if (double t0 = -kInfinity, t1 = kInfinity;
                        clip_ray(boxes[i], world, t0, t1) &&
                        capsules[i].meets_line(world.o, world.d) && s.cull_meets(i, local))
                        return true;
                return false;
            };
            for (const double footprint : {0.0, 0.05, 0.5, 2.0, kExactWidth, 3 * kExactWidth}) {
                // Outside a traversal: no directions across, the instance's bound.
                RayFootprint f = width_footprint(footprint);
                f.widest = widest;
                for (const Ray& r : local_rays) {
                    const Ray world{xf.point(r.o), xf.vector(r.d)};
                    const Ray local = with(xf.inverse_ray(world), f);
                    Crossing c;
                    const bool hit = s.intersect(local, 0.0, kInfinity, c);
                    hits += hit;
                    if (hit) {
                        EXPECT_TRUE(kept(world, local))
                            << "widest " << widest << ", footprint " << footprint;
                    }
                    culled += !kept(world, local);
                }
            }
        }
        EXPECT_GT(hits, 500) << "widest " << widest;
        EXPECT_GT(culled, last_culled) << "widest " << widest;
        last_culled = culled;
    }
}

TEST(FilteredCloseUps, EachInstanceIsCulledByItsOwnWidestFootprint) {
    const SphereShape ball({2, 1, 2}, 0.8);
    expect_instances_culled_by_their_own_bound(long_hook());
    expect_instances_culled_by_their_own_bound(ball);
    expect_instances_culled_by_their_own_bound(bitten_tori());
}

// The accelerator hands each instance its own bound (AccelObject::widest_footprint): it
// answers as the shape does when given each instance's bound, for footprints narrower and wider
// than it, the two instances' bounds apart.
TEST(FilteredCloseUps, TheAcceleratorHandsEachInstanceItsBound) {
    const HookLattice h = hook_lattice(long_hook());
    const SubRayShape& s = *h.exact;
    const Transform near = Transform::translate({3, -2, 5}) * Transform::rotate({1, 2, 3}, 0.7);
    const Transform far = Transform::translate({3, 20, 5});
    const double near_widest = 0.3 * kExactWidth;
    const std::vector<AccelObject> objects{{&s, &near, near_widest}, {&s, &far, kInfinity}};
    const EmbreeAccel accel(objects);
    // The closest crossing of either instance, each tested with its own bound.
    const auto expected = [&](const Ray& world, double near_bound, AccelHit& out) {
        bool found = false;
        for (std::uint32_t i = 0; i < 2; ++i) {
            const Transform& xf = *objects[i].xf;
            RayFootprint f = *world.footprint;
            across_in_object(*world.footprint, xf.inverse_map(), xf.is_identity(), true,
                             i == 0 ? near_bound : kInfinity, f);
            Crossing c;
            if (s.intersect(with(xf.inverse_ray(world), f), 0.0, found ? out.t : kInfinity, c))
                found = true, out = {c.t, i, c, {}};
        }
        return found;
    };
    int near_hits = 0, differ_unbounded = 0;
    for (const double footprint : {0.05, 2.0, 3 * kExactWidth}) {
        const RayFootprint f = width_footprint(footprint);
        for (const Ray& r : rays(1500)) {
            const Ray world{near.point(r.o), near.vector(r.d), &f};
            AccelHit a, e, wide;
            const bool found = accel.intersect(world, 0.0, kInfinity, a);
            ASSERT_EQ(found, expected(world, near_widest, e)) << "footprint " << footprint;
            if (!found) continue;
            EXPECT_EQ(a.object, e.object);
            EXPECT_EQ(a.t, e.t);
            EXPECT_EQ(a.crossing.coverage, e.crossing.coverage);
            if (a.object != 0) continue;
            ++near_hits;
            differ_unbounded += !expected(world, kInfinity, wide) || wide.t != e.t;
        }
    }
    EXPECT_GT(near_hits, 1000);
    EXPECT_GT(differ_unbounded, 100);  // the bound matters for these rays
}

// A ray leaving a sheet skips its own lattice for the sheet's distance from the surface: with
// the primitive's crossings, the sub-rays' widest footprint (points on the surface averaged
// across it; in renders far less than the tables' 2 cells, so that strands shadow strands).
TEST(FilteredCloseUps, SheetsOfThePrimitivesCrossingsSkipThemselvesForTheirWidthOnly) {
    const HookLattice h = hook_lattice();
    EXPECT_EQ(h.exact->surface_tolerance(), kExactWidth);
    EXPECT_EQ(h.tables_only->surface_tolerance(), 2 * kFine.cell);
}

// A ray's direction need not be a unit vector in the primitive's frame (scaled instances): the
// footprint scales with it, so twice the direction and half the footprint is the same ray and
// footprint, answered at half the parameter.
TEST(FilteredCloseUps, LongerDirectionsAreTheSameRay) {
    const HookLattice h = hook_lattice();
    for (const double width : {1e-9, 0.5, 2.0}) {
        for (const bool shadow : {false, true}) {
            int hits = 0;
            for (const Ray& r : rays(2000)) {
                Crossing a, b;
                const RayFootprint fa = width_footprint(width, 0, shadow);
                const RayFootprint fb = width_footprint(width / 2, 0, shadow);
                const bool ha = h.exact->intersect(with(r, fa), 0.0, kInfinity, a);
                const bool hb = h.exact->intersect({r.o, r.d * 2.0, &fb}, 0.0, kInfinity, b);
                ASSERT_EQ(ha, hb) << "width " << width;
                if (!ha) continue;
                ++hits;
                EXPECT_NEAR(b.t, a.t / 2, 1e-9);
                EXPECT_NEAR(b.coverage, a.coverage, 1e-6);
                EXPECT_NEAR(length(b.stored.n - a.stored.n), 0.0, 1e-9);
            }
            EXPECT_GT(hits, 300);
        }
    }
}

// How far a ray may go (tmax: for camera rays in the accelerator, the closest crossing found
// so far) only cuts the sheet, as for the tables: the answer is the same whatever order the
// accelerator meets objects in.
TEST(FilteredCloseUps, TheSheetIsCutAtTmaxNotMadeOfWhatLiesBeforeIt) {
    const HookLattice h = hook_lattice();
    for (const double width : {1e-9, 1.0}) {
        const RayFootprint f = width_footprint(width);
        for (const Ray& line : rays(3000)) {
            const Ray r = with(line, f);
            Crossing whole, cut;
            if (!h.exact->intersect(r, 0.0, kInfinity, whole)) continue;
            for (const double tmax : {whole.t - 0.01, whole.t + 0.01}) {
                const bool hit = h.exact->intersect(r, 0.0, tmax, cut);
                ASSERT_EQ(hit, whole.t < tmax);
                if (!hit) continue;
                EXPECT_EQ(cut.t, whole.t);
                EXPECT_EQ(cut.coverage, whole.coverage);
            }
        }
    }
}

// Camera rays without a footprint (width 0: the camera in the box, say) get their own line's
// crossing and normal from a primitive that answers, the continuous limit of a vanishing one.
TEST(FilteredCloseUps, RaysWithoutAFootprintGetTheirLinesCrossing) {
    const HookLattice h = hook_lattice();
    int hits = 0;
    for (const Ray& r : rays(3000)) {
        Crossing exact, got;
        const bool e = hook().intersect(r, 0.0, kInfinity, exact);
        ASSERT_EQ(h.exact->intersect(r, 0.0, kInfinity, got), e);
        if (!e) continue;
        ++hits;
        EXPECT_NEAR(got.t, exact.t, 1e-9);
        EXPECT_EQ(got.coverage, 1.0f);
        EXPECT_NEAR(length(got.stored.n - normalize(hook().normal(r, exact))), 0.0, 1e-9);
    }
    EXPECT_GT(hits, 500);
}

// How many of 3000 rays of a vanishing footprint a primitive in a {4, 2, 4} box answers
// differently with its own crossings asked for than without them.
int differing_answers(const Shape& primitive) {
    const TableContext ctx{{4, 2, 4}, 1.0, 1.0, &primitive};
    const Encoding& e = find_encoding("coverage");
    const RasterizeResult raster = rasterize(ctx);
    const ByteBuffer payload = e.build(raster.raw, ctx, {});
    const std::vector<FilterLevel> levels{
        {e.open(payload.data(), payload.size(), raster.hits, ctx), ctx}};
    const SubRayShape asked(ctx, levels.back().table, e.error_bound(ctx, {}), kExactWidth);
    const FilteredLatticeShape tables(levels, LatticeFilter::kSmooth, e.error_bound(ctx, {}));
    const RayFootprint vanishing = width_footprint(1e-9);
    int differ = 0;
    for (const Ray& line : rays(3000)) {
        const Ray r = with(line, vanishing);
        Crossing a, b;
        const bool ha = asked.intersect(r, 0.0, kInfinity, a), hb = tables.intersect(r, 0.0, kInfinity, b);
        differ += ha != hb || (ha && (a.t != b.t || a.coverage != b.coverage));
    }
    return differ;
}

// A row of `parts` beads across the box.
ChainShape beads(std::size_t parts) {
    std::vector<ChainSphere> b;
    for (std::size_t i = 0; i < parts; ++i)
        b.push_back({{0.5 + 3.0 * double(i) / double(parts - 1), 1.0, 2.0}, 0.2});
    return ChainShape(b, {});
}

// Without its table (scene_lattices loads none for a primitive answered by its crossings and
// held by no CSG tree) the shape answers every ray as with it, bit for bit, camera and shadow
// rays with footprints or none; its spans and `inside` are the primitive's own. A level
// without a table for a primitive that does not answer by its crossings is refused.
TEST(FilteredCloseUps, APrimitiveAnsweredByItsCrossingsNeedsNoTable) {
    const HookLattice h = hook_lattice(long_hook());
    TableContext ctx = kFine;
    ctx.primitive = &long_hook();
    const SubRayShape bare(ctx, nullptr, 0.0, kExactWidth);
    EXPECT_EQ(bare.bounds().lo, h.exact->bounds().lo);
    EXPECT_EQ(bare.bounds().hi, h.exact->bounds().hi);
    int hits = 0, spans = 0;
    for (const RayFootprint& f :
         {width_footprint(0.4, 0.01, false), width_footprint(0.8, -0.05, true),
          width_footprint(0, 0, false)}) {
        for (const Ray& line : rays(2000)) {
            const Ray r = with(line, f);
            Crossing a, b;
            const bool ha = h.exact->intersect(r, 0.0, kInfinity, a);
            ASSERT_EQ(bare.intersect(r, 0.0, kInfinity, b), ha);
            ASSERT_EQ(bare.occluded(r, 0.0, 20.0), h.exact->occluded(r, 0.0, 20.0));
            if (!ha) continue;
            ++hits;
            EXPECT_EQ(a.t, b.t);
            EXPECT_EQ(a.coverage, b.coverage);
            EXPECT_EQ(a.sub_rays, b.sub_rays);
            EXPECT_EQ(a.stored.n, b.stored.n);
        }
    }
    for (const Ray& r : rays(500)) {
        SpanList own, got;
        long_hook().spans(r, own);
        bare.spans(r, got);
        ASSERT_EQ(got.size(), own.size());
        for (std::size_t k = 0; k < own.size(); ++k) EXPECT_EQ(got[k].in.t, own[k].in.t);
        spans += static_cast<int>(own.size());
        const Vec3 p = r.o + r.d * 2.0;
        EXPECT_EQ(bare.inside(p), long_hook().inside(p));
    }
    EXPECT_GT(hits, 1000);
    EXPECT_GT(spans, 100);
    EXPECT_THROW(FilteredLatticeShape({{nullptr, ctx}}, LatticeFilter::kSmooth, 0.0),
                 std::logic_error);
}

// A chain answers from its crossings whatever its parts: its sub-rays test only the parts near
// the ray (PartBoxes, through a tree of their boxes past kTreeFrom parts), not every part. Its
// answers are its line's crossings (a vanishing footprint), so they differ from the tables'.
TEST(FilteredCloseUps, ChainsOfAnyPartsAnswerFromTheirCrossings) {
    for (const std::size_t parts : {std::size_t(kMaxExactCost) + 1, std::size_t(400)}) {
        const ChainShape row = beads(parts);
        EXPECT_GT(row.intersect_cost(), kMaxExactCost);
        EXPECT_TRUE(answered_by_primitive(row));
        EXPECT_GT(differing_answers(row), 500) << parts << " parts";
        const TableContext ctx{{4, 2, 4}, 1.0, 1.0, &row};
        const Encoding& e = find_encoding("coverage");
        const RasterizeResult raster = rasterize(ctx);
        const ByteBuffer payload = e.build(raster.raw, ctx, {});
        const SubRayShape asked(ctx, e.open(payload.data(), payload.size(), raster.hits, ctx),
                                e.error_bound(ctx, {}), kExactWidth);
        int hits = 0;
        for (const Ray& r : rays(3000)) {  // without a footprint
            Crossing exact, got;
            const bool hit = row.intersect(r, 0.0, kInfinity, exact);
            ASSERT_EQ(asked.intersect(r, 0.0, kInfinity, got), hit) << parts << " parts";
            if (!hit) continue;
            ++hits;
            EXPECT_NEAR(got.t, exact.t, 1e-9);
        }
        EXPECT_GT(hits, 300) << parts << " parts";
    }
}

// A mesh descends its own hierarchy: one of many more triangles than kMaxExactCost is answered
// from its crossings (a sheet of 2 x 12 x 8 triangles); a CSG tree costs its leaves' costs, so
// one with such a chain as a leaf keeps to its tables, and so does one of six tori (a quartic
// costs 12), where one of five does not (answered_by_primitive: the answer plan's rule, which
// gives such a primitive its crossings only past the build budget; the shape answers by them
// whenever it is given a width).
TEST(FilteredCloseUps, MeshesAnswerExactlyAndTreesCostTheirLeaves) {
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
    ASSERT_GT(static_cast<double>(sheet.part_count()), kMaxExactCost);
    EXPECT_LE(sheet.intersect_cost(), kMaxExactCost);
    EXPECT_TRUE(answered_by_primitive(sheet));
    EXPECT_GT(differing_answers(sheet), 500);

    CsgShape tree;
    const auto small = static_cast<std::size_t>(kMaxExactCost) / 2;
    const int a = tree.add_leaf({std::make_shared<ChainShape>(beads(small)), {}, 1});
    const int b = tree.add_leaf({std::make_shared<ChainShape>(beads(small + 1)), {}, 2});
    tree.set_root(tree.add_node(CsgOp::kUnion, {a, b}));
    EXPECT_EQ(tree.intersect_cost(), double(2 * small + 1));
    EXPECT_FALSE(answered_by_primitive(tree));

    const auto tori = [](int count) {
        CsgShape t;
        std::vector<int> leaves;
        for (int i = 0; i < count; ++i) {
            const PlacedShape torus = make_torus({0.7 + 0.65 * i, 1, 2}, {1, 0.3 * i, 0.5}, 0.5, 0.15);
            leaves.push_back(t.add_leaf({torus.shape, torus.placement, static_cast<std::uint32_t>(i + 1)}));
        }
        t.set_root(t.add_node(CsgOp::kUnion, leaves));
        return t;
    };
    EXPECT_EQ(tori(5).intersect_cost(), 60.0);
    EXPECT_TRUE(answered_by_primitive(tori(5)));
    EXPECT_GT(differing_answers(tori(5)), 300);
    EXPECT_FALSE(answered_by_primitive(tori(6)));
    EXPECT_GT(differing_answers(tori(6)), 300);  // given a width, it answers by its crossings
}

}  // namespace
}  // namespace lat
