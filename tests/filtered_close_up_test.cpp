// Close-ups through filtered lattices (issue 10): with levels of detail, a ray whose footprint is
// far narrower than the finest table's cell gets the primitive's own crossing (exact_weight),
// blended with the table's sheet on the way there.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hook_primitive.h"
#include "lattice/encoding.h"
#include "lattice/filtered_shape.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

using test::hook;
const TableContext& kContext = test::kHookContext;

// The hook's coverage table behind the smooth filter, with and without exact close-ups.
struct HookLattice {
    ByteBuffer payload;  // the table reads it in place
    std::unique_ptr<FilteredLatticeShape> exact_close, tables_only;
};

HookLattice hook_lattice() {
    const Encoding& e = find_encoding("coverage");
    const RasterizeResult r = rasterize(kContext);
    HookLattice h;
    h.payload = e.build(r.raw, kContext, {});
    std::shared_ptr<const LatticeTable> table =
        e.open(h.payload.data(), h.payload.size(), r.hits, kContext);
    const std::vector<FilterLevel> levels{{table, kContext}};
    const double error = e.error_bound(kContext, {});
    h.exact_close = std::make_unique<FilteredLatticeShape>(levels, LatticeFilter::kSmooth, error, true);
    h.tables_only = std::make_unique<FilteredLatticeShape>(levels, LatticeFilter::kSmooth, error, false);
    return h;
}

// The footprint width (unit directions, no spread) whose level lies `past` levels beyond the
// only level's (lod_level).
double width_past(double past) {
    return kContext.cell / (kCellPerFootprint * std::exp2(past));
}

// Lines through the hook's box, from outside it.
std::vector<Ray> lines(int n) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Bounds3 box = expand(Bounds3{{0, 0, 0}, Vec3{double(kContext.cells[0]), double(kContext.cells[1]),
                                                      double(kContext.cells[2])} * kContext.cell},
                               0.5);
    auto point = [&] { return box.lo + Vec3{u(rng), u(rng), u(rng)} * (box.hi - box.lo); };
    std::vector<Ray> out;
    for (int i = 0; i < n; ++i) {
        const Vec3 p = point(), q = point();
        out.push_back({p - (q - p) * 4.0, (q - p) / length(q - p)});
    }
    return out;
}

TEST(FilteredCloseUps, FootprintsFarNarrowerThanTheFinestCellGetThePrimitivesCrossing) {
    const HookLattice h = hook_lattice();
    set_ray_footprint({width_past(kExactTo + 0.5), 0, false});
    int hits = 0, tables_differ = 0;
    for (const Ray& r : lines(5000)) {
        Crossing exact, got, table;
        const bool e = hook().intersect(r, 0.0, kInfinity, exact);
        ASSERT_EQ(h.exact_close->intersect(r, 0.0, kInfinity, got), e);
        if (h.tables_only->intersect(r, 0.0, kInfinity, table) != e ||
            (e && std::abs(table.t - exact.t) > 1e-6))
            ++tables_differ;
        if (!e) continue;
        ++hits;
        EXPECT_NEAR(got.t, exact.t, 1e-9);
        EXPECT_EQ(got.coverage, 1.0f);
        const Vec3 n = normalize(hook().normal(r, exact));
        EXPECT_NEAR(length(h.exact_close->normal(r, got) - n), 0.0, 1e-9);
    }
    set_ray_footprint({});
    EXPECT_GT(hits, 500);
    // Without exact close-ups the same rays read the table: most hits differ.
    EXPECT_GT(tables_differ, hits / 2);
}

TEST(FilteredCloseUps, TheRampBlendsTheTablesSheetWithTheCrossing) {
    const HookLattice h = hook_lattice();
    const double past = 0.5 * (kExactFrom + kExactTo);
    ASSERT_EQ(exact_weight(past), 0.5);
    set_ray_footprint({width_past(past), 0, false});
    int blended = 0;
    for (const Ray& r : lines(5000)) {
        Crossing exact, got, table;
        const double e = hook().intersect(r, 0.0, kInfinity, exact) ? 1.0 : 0.0;
        const double a = h.tables_only->intersect(r, 0.0, kInfinity, table) ? double(table.coverage) : 0.0;
        const double want = 0.5 * a + 0.5 * e;
        const bool hit = h.exact_close->intersect(r, 0.0, kInfinity, got);
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

// Footprints the finest level resolves, and rays with none (width 0 asks for the finest level),
// read the tables alone: the same answers, to the bit, as without exact close-ups.
TEST(FilteredCloseUps, OtherFootprintsReadTheTablesAlone) {
    const HookLattice h = hook_lattice();
    for (const double width : {0.0, width_past(kExactFrom - 0.01), width_past(0), width_past(-2)}) {
        set_ray_footprint({width, 0, false});
        for (const Ray& r : lines(2000)) {
            Crossing a, b;
            const bool ha = h.exact_close->intersect(r, 0.0, kInfinity, a);
            ASSERT_EQ(ha, h.tables_only->intersect(r, 0.0, kInfinity, b)) << "width " << width;
            if (!ha) continue;
            EXPECT_EQ(a.t, b.t);
            EXPECT_EQ(a.coverage, b.coverage);
            EXPECT_EQ(a.stored.n.x, b.stored.n.x);
            EXPECT_EQ(a.stored.n.y, b.stored.n.y);
            EXPECT_EQ(a.stored.n.z, b.stored.n.z);
        }
    }
    set_ray_footprint({});
}

}  // namespace
}  // namespace lat
