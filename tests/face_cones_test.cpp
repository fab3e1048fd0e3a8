// The rasterizer's bundled culling (a part sphere's cone against a whole face, its rows bounded
// before they are visited) against the plain per-ray answer: every pair traced against every
// part, on random and adversarial primitives (grazing rays, rays through part joints, parts that
// touch the box, degenerate lattices).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "geometry/chain.h"
#include "geometry/parts.h"
#include "lattice/boundary_grid.h"
#include "lattice/face_cones.h"
#include "lattice/octahedral.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

// cone_rows must hold every row where ConeRows::row finds an interval, but p's own row when p
// lies on the face and the sphere is off its plane (there the interval holds p alone); its gap
// none of them.
void expect_rows_bounded(const Vec3& p, const PartSphere& s, const FaceLayout& f) {
    int c0 = 0, c1 = -1, g0 = 0, g1 = -1;
    const bool any = cone_rows(p, s, f, c0, c1, g0, g1);
    const ConeRows cone(p, s, f);
    const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
               va = static_cast<std::size_t>(f.va);
    for (int v = 0; v < f.nv; ++v) {
        double lo, hi;
        if (!cone.row(v, lo, hi)) continue;
        const bool only_p = p[ax] == f.level && v == p[va] && lo > p[ua] - 1 && hi < p[ua] + 1;
        if (only_p) continue;
        EXPECT_TRUE(any && v >= c0 && v <= c1 && (v < g0 || v > g1))
            << "p " << p.x << " " << p.y << " " << p.z << ", sphere " << s.c.x << " " << s.c.y << " "
            << s.c.z << " r " << s.r << ", face axis " << f.axis << " level " << f.level << ", row " << v;
    }
}

TEST(ConeRows, HoldEveryRowTheConeReaches) {
    const BoundaryGrid grid({6, 5, 9});
    std::vector<FaceLayout> faces;
    for (int f = 0; f < 6; ++f) faces.push_back(layout_face(grid, f));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> x(-1, 10), r(0.05, 3);
    std::uniform_int_distribution<std::uint32_t> pick(0, grid.count() - 1);
    std::vector<PartSphere> spheres;
    for (int i = 0; i < 300; ++i) spheres.push_back({{x(rng), x(rng), x(rng)}, r(rng), 0});
    // Adversarial: centred on grid points and planes, touching faces, radius exactly at a grid
    // plane's distance (rays along grid lines graze them).
    for (int i = 0; i < 6; ++i)
        for (double rad : {0.5, 1.0, std::sqrt(0.5)}) {
            spheres.push_back({{double(i), 2.0, 3.0}, rad, 0});
            spheres.push_back({{0.5 * i, 0.0, 4.5}, rad, 0});
            spheres.push_back({{3.0, 2.5, i + rad}, rad, 0});
        }
    for (const PartSphere& s : spheres)
        for (int n = 0; n < 12; ++n) {
            const Vec3 p = to_vec(grid.point(pick(rng)));
            for (const FaceLayout& f : faces) expect_rows_bounded(p, s, f);
        }
}

// The per-ray answer for every valid pair: each part in turn, the closest crossing kept (ties to
// the earlier part), as a loop over all parts finds it; a start inside the solid hits at 0.
struct Expected {
    float t;
    std::uint16_t part, nu, nv;
};
std::map<std::pair<std::uint32_t, std::uint32_t>, Expected> per_ray(const Shape& s, const TableContext& ctx) {
    const BoundaryGrid g(ctx.cells);
    std::map<std::pair<std::uint32_t, std::uint32_t>, Expected> out;
    for (std::uint32_t a = 0; a < g.count(); ++a) {
        const Vec3 p = to_vec(g.point(a));
        const bool inside = s.inside(p * ctx.cell);
        for (std::uint32_t b = 0; b < g.count(); ++b) {
            if (a == b || !BoundaryGrid::valid_pair(g.faces(g.point(a)), g.faces(g.point(b)))) continue;
            const Ray r{p * ctx.cell, (to_vec(g.point(b)) - p) * ctx.cell};
            Crossing best;
            double tmax = 1.0 + 1e-12;
            bool hit = false;
            for (std::size_t i = 0; i < ShapeParts(s).part_count(); ++i) {
                Crossing c;
                if (ShapeParts(s).intersect_part(i, r, 0.0, tmax, c)) tmax = c.t, best = c, hit = true;
            }
            if (inside) best = nearest_crossing(s, r), hit = true;
            if (!hit) continue;
            const Oct o = oct_encode(s.normal(r, best), kRawNormalBits);
            out[{a, b}] = {inside ? 0.0f : static_cast<float>(std::min(1.0, tmax)),
                           static_cast<std::uint16_t>(best.part), static_cast<std::uint16_t>(o.u),
                           static_cast<std::uint16_t>(o.v)};
        }
    }
    return out;
}

void expect_same_as_per_ray(const Shape& s, const TableContext& ctx, const char* what) {
    const RasterizeResult r = rasterize(ctx);
    const auto expected = per_ray(s, ctx);
    ASSERT_EQ(r.raw.size(), expected.size()) << what;
    for (const RawHit& h : r.raw.flatten()) {
        const auto it = expected.find({h.a, h.b});
        ASSERT_NE(it, expected.end()) << what;
        EXPECT_EQ(h.t, it->second.t) << what << ": " << h.a << " -> " << h.b;
        EXPECT_EQ(h.part, it->second.part) << what;
        EXPECT_EQ(h.nu, it->second.nu) << what;
        EXPECT_EQ(h.nv, it->second.nv) << what;
    }
}

TEST(BundledRasterize, SameHitsAsPerRayOnRandomChains) {
    for (unsigned seed : {1u, 2u, 3u}) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(0.3, 4.7), rr(0.15, 0.8);
        std::vector<ChainSphere> spheres;
        std::vector<ChainCylinder> cyl;
        for (int i = 0; i < 5; ++i) spheres.push_back({{u(rng), u(rng), u(rng)}, rr(rng)});
        for (int i = 0; i + 1 < 5; ++i)
            cyl.push_back({i, i + 1, std::min(spheres[i].radius, spheres[i + 1].radius)});
        const ChainShape s(spheres, cyl);
        expect_same_as_per_ray(s, {{5, 4, 5}, 1.0, 1.0, &s}, "random chain");
        expect_same_as_per_ray(s, {{10, 8, 10}, 0.5, 1.0, &s}, "random chain, sigma^-1 = 2");
    }
}

TEST(BundledRasterize, SameHitsAsPerRayOnAdversarialChains) {
    // Grazing: rays along grid lines touch spheres of radius 1/2 centred half a cell off them,
    // and cylinders whose side lies on a grid plane.
    const ChainShape grazing({{{2, 2, 2.5}, 0.5}, {{2, 2, 1.5}, 0.5}, {{1, 3, 1}, 1.0}, {{3, 1, 1}, 1.0}},
                             {{0, 1, 0.5}, {2, 3, 1.0}});
    expect_same_as_per_ray(grazing, {{4, 4, 4}, 1.0, 1.0, &grazing}, "grazing");
    // Joints on grid points, where rays pass through a sphere and both cylinders ending in it,
    // and a sharp bend.
    const ChainShape joints({{{1, 1, 1}, 0.6}, {{2, 2, 2}, 0.6}, {{3, 1, 2}, 0.6}, {{1, 1, 3}, 0.4}},
                            {{0, 1, 0.6}, {1, 2, 0.6}, {2, 3, 0.4}});
    expect_same_as_per_ray(joints, {{4, 3, 4}, 1.0, 1.0, &joints}, "joints");
    // Parts that touch and cross the box's faces (entries inside the solid) and fill it.
    const ChainShape touching({{{1, 1, 1}, 1.0}, {{0, 2, 3}, 1.5}, {{2, 0.5, 4}, 0.5}}, {{0, 1, 1.0}, {1, 2, 0.5}});
    expect_same_as_per_ray(touching, {{2, 2, 4}, 1.0, 1.0, &touching}, "touching");
    // Degenerate lattices: one cell, a row of cells, a slab one cell thick.
    const ChainShape small({{{0.5, 0.5, 0.5}, 0.3}, {{0.5, 0.5, 2.5}, 0.3}}, {{0, 1, 0.3}});
    expect_same_as_per_ray(small, {{1, 1, 1}, 1.0, 1.0, &small}, "one cell");
    expect_same_as_per_ray(small, {{1, 1, 3}, 1.0, 1.0, &small}, "a row of cells");
    const ChainShape flat({{{0.5, 0.5, 0.5}, 0.5}, {{3.5, 2.5, 0.5}, 0.25}}, {{0, 1, 0.25}});
    expect_same_as_per_ray(flat, {{4, 3, 1}, 1.0, 1.0, &flat}, "a slab");
}

}  // namespace
}  // namespace lat
