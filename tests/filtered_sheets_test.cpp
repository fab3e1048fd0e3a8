// A filtered lattice's sheets: a camera ray whose footprint holds a bar with another far
// behind it gets a sheet at each bar, where one blended sheet lay between them (inside the
// object: in shadow from every light); a bar too faint for a sheet of its own leaves the one
// sheet at the other bar. Splitting keeps the footprint's coverage.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "geometry/chain.h"
#include "lattice/encoding.h"
#include "lattice/filtered_shape.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

// Two upright bars in a box 6 x 10 x 4 cells of 1, seen along +y: one at depth y = 1.5 left of
// x = 3, one at y = 8.5 right of it, of radius `back_radius`.
constexpr double kFrontY = 1.5, kBackY = 8.5;
ChainShape two_bars(double back_radius) {
    const double r = 0.35;
    return ChainShape({{{2.0, kFrontY, 0.2}, r}, {{2.0, kFrontY, 3.8}, r},
                       {{3.0, kBackY, 0.2}, back_radius}, {{3.0, kBackY, 3.8}, back_radius}},
                      {{0, 1, r}, {2, 3, back_radius}});
}

struct BarsLattice {
    ChainShape primitive;
    ByteBuffer payload;
    std::unique_ptr<FilteredLatticeShape> shape;
};

std::unique_ptr<BarsLattice> bars_lattice(double back_radius) {
    auto l = std::make_unique<BarsLattice>(BarsLattice{two_bars(back_radius), {}, nullptr});
    const TableContext ctx{{6, 10, 4}, 1.0, 1.0, &l->primitive};
    const Encoding& e = find_encoding("coverage");
    const RasterizeResult r = rasterize(ctx);
    l->payload = e.build(r.raw, ctx, {});
    l->shape = std::make_unique<FilteredLatticeShape>(
        std::vector<FilterLevel>{{e.open(l->payload.data(), l->payload.size(), r.hits, ctx), ctx}},
        LatticeFilter::kSmooth, e.error_bound(ctx, {}));
    return l;
}

// Camera rays along +y midway between the bars' lines, a cell wide: the footprint blends the
// pairs on either side, each of which meets one bar.
struct Answer {
    int count = 0;
    std::array<SheetCrossing, kMaxSheets> sheets;
    Crossing one;  // the ray's one blended sheet (intersect)
};
Answer answer(const FilteredLatticeShape& shape, double z) {
    RayFootprint f;
    f.width0 = 1.0;
    const Ray ray{{2.5, -1.0, z}, {0, 1, 0}, &f};
    Answer a;
    a.count = shape.sheets(ray, 0.0, kInfinity, a.sheets);
    EXPECT_TRUE(shape.intersect(ray, 0.0, kInfinity, a.one));
    return a;
}

double depth(const Crossing& c) { return c.stored.p.y; }

TEST(FilteredSheets, BarsFarApartInDepthMakeASheetEach) {
    const auto l = bars_lattice(0.35);
    for (const double z : {1.0, 2.0, 2.25, 3.0}) {
        const Answer a = answer(*l->shape, z);
        ASSERT_EQ(a.count, 2) << "z " << z;
        EXPECT_NEAR(depth(a.sheets[0].crossing), kFrontY, 0.5) << "z " << z;
        EXPECT_NEAR(depth(a.sheets[1].crossing), kBackY, 0.5) << "z " << z;
        EXPECT_LT(a.sheets[0].crossing.t, a.sheets[1].crossing.t);
        // Composited front to back, the sheets cover what the one blended sheet covers.
        const double a0 = a.sheets[0].crossing.coverage, a1 = a.sheets[1].crossing.coverage;
        EXPECT_GT(a0, 0.25);
        EXPECT_GT(a1, 0.25);
        EXPECT_NEAR(a0 + (1 - a0) * a1, double(a.one.coverage), 1e-5) << "z " << z;
        // Each is shaded with its bar's normals, turned to the camera.
        EXPECT_LT(a.sheets[0].crossing.stored.n.y, -0.5);
        EXPECT_LT(a.sheets[1].crossing.stored.n.y, -0.5);
    }
}

TEST(FilteredSheets, AFaintBarLeavesTheOneSheetAtTheOther) {
    const auto l = bars_lattice(0.08);
    for (const double z : {1.0, 2.0, 2.25, 3.0}) {
        const Answer a = answer(*l->shape, z);
        ASSERT_EQ(a.count, 1) << "z " << z;
        EXPECT_NEAR(depth(a.sheets[0].crossing), kFrontY, 0.5) << "z " << z;
        EXPECT_FLOAT_EQ(a.sheets[0].crossing.coverage, a.one.coverage);
    }
}

}  // namespace
}  // namespace lat
