// Lattice shapes in CSG: a hit carries the point and normal its table stored, and a CSG tree
// hands them on, moved into its own coordinates (not the ray's point, which lies off them).
#include <gtest/gtest.h>

#include <random>

#include "csg/csg_shape.h"
#include "geometry/chain.h"
#include "geometry/sphere.h"
#include "lattice/encoding.h"
#include "lattice/lattice_shape.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

struct HookLattice {
    ChainShape hook{{{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}},
                    {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}}};
    TableContext ctx{{4, 2, 4}, 1.0, 1.0, &hook};  // coarse: stored points lie well off rays
    std::shared_ptr<const Shape> shape;

    HookLattice() {
        const Encoding& e = find_encoding("hash14");
        const RasterizeResult r = rasterize(ctx);
        auto payload = std::make_shared<ByteBuffer>(e.build(r.raw, ctx, {}));
        std::shared_ptr<LatticeTable> table = e.open(payload->data(), payload->size(), r.hits, ctx);
        table->hold(payload);
        shape = make_lattice_shape(table, ctx, e.error_bound(ctx, {}));
    }
};

TEST(LatticeInCsg, ALeafInADifferenceIsShadedAtItsStoredPoint) {
    const HookLattice lattice;
    const Transform xf = Transform::translate({10, -3, 2}) * Transform::rotate({0, 0, 1}, 0.7);
    // The hook, moved, minus a ball that takes a bite out of its top left corner.
    CsgShape csg;
    const int a = csg.add_leaf({lattice.shape, xf, 0, -1});
    const int b = csg.add_leaf({std::make_shared<SphereShape>(xf.point({1, 1, 3.4}), 0.4),
                                Transform{}, 1, -1});
    csg.set_root(csg.add_node(CsgOp::kDifference, {a, b}));

    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    int compared = 0, off_ray = 0, bitten = 0;
    for (int n = 0; n < 20000; ++n) {
        const Vec3 target = xf.point({2 + 2 * u(rng), 1 + u(rng), 2 + 2 * u(rng)});
        const Vec3 d = normalize(Vec3{u(rng), u(rng), u(rng)});
        const Ray ray{target - d * 20, d};
        Crossing c;
        if (!csg.intersect(ray, 0, kInfinity, c)) continue;
        const SurfacePoint s = csg.surface(ray, c);
        if (c.leaf_index() != 0) {  // the ball's inside surface, exact
            ++bitten;
            EXPECT_LT(length(s.p - ray.at(c.t)), 1e-9);
            continue;
        }
        // What the lattice alone says about the same crossing, in its own coordinates.
        const Ray local = xf.inverse_ray(ray);
        SpanList spans;
        lattice.shape->spans(local, spans);
        ASSERT_EQ(spans.size(), 1u);
        const Crossing& own = c.part == 0 ? spans[0].in : spans[0].out;
        ASSERT_TRUE(own.has_stored);
        EXPECT_LT(length(s.p - xf.point(own.stored.p)), 1e-9) << n;
        EXPECT_LT(length(s.n - normalize(xf.normal(own.stored.n))), 1e-9) << n;
        off_ray += length(s.p - ray.at(c.t)) > 1e-3 ? 1 : 0;
        ++compared;
    }
    EXPECT_GT(compared, 1000);
    EXPECT_GT(bitten, 10);
    EXPECT_GT(off_ray, compared / 4);  // the old bug (the ray's point) would fail above
}

TEST(LatticeInCsg, ShapesAnswerWithTheStoredSurface) {
    const HookLattice lattice;
    const Ray ray{{2, -5, 2.9}, {0, 1, 0}};
    Crossing c;
    ASSERT_TRUE(lattice.shape->intersect(ray, 0, kInfinity, c));
    ASSERT_TRUE(c.has_stored);
    const SurfacePoint s = lattice.shape->surface(ray, c);
    EXPECT_EQ(s.p, c.stored.p);
    EXPECT_EQ(s.n, c.stored.n);
    EXPECT_NEAR(length(s.n), 1.0, 1e-6);
}

}  // namespace
}  // namespace lat

namespace lat {
namespace {

// The line parallel to `line` (shifted across it) that the shape's test, on the line mapped
// by xf and back, accepts last: within rounding of the capsule's surface.
Ray grazing(const LatticeFrame& frame, std::size_t i, const Transform& xf, const Ray& line) {
    Vec3 e, f;
    orthonormal_basis(line.d, e, f);
    const auto kept = [&](double s) {
        const Ray r{xf.point(line.o + e * s), xf.vector(line.d)};
        return frame.cull_meets(i, xf.inverse_ray(r));
    };
    double in = -6, out = 6;
    for (double s = -6; s <= 6; s += 0.05)
        if (kept(s)) {
            in = s;
            break;
        }
    if (!kept(in)) return line;
    for (int k = 0; k < 80; ++k) {
        const double mid = 0.5 * (in + out);
        (kept(mid) ? in : out) = mid;
    }
    return {line.o + e * in, line.d};
}

// The accelerator rejects rays by a cull part's capsule placed in world space before mapping
// them into the lattice's space (CullParts::cull_capsule), kept in float (FloatCapsule): both must
// accept every line the shape's own test accepts, under rotations, uniform and non-uniform
// scales, a shear (condition number near 400) and far translations, for lines found within
// rounding of the capsules' surfaces, with origins near, 10^9 and 10^13 away; and they do reject
// lines.
TEST(LatticeCulling, WorldCapsulesHoldEveryLineTheShapeAccepts) {
    const HookLattice lattice;
    const LatticeFrame frame(lattice.ctx, 0.3);
    ASSERT_GT(frame.cull_count(), 1u);
    Affine shear;
    shear.m = Mat3{{Vec3{1, 20, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}}};
    const Transform xfs[] = {
        Transform{},
        Transform::translate({10, -3, 2}) * Transform::rotate({1, 2, 3}, 0.7) *
            Transform::scale({2.5, 2.5, 2.5}),
        Transform::rotate({0, 1, 0}, 2.1) * Transform::scale({1, 3, 0.5}),
        Transform::translate({4e3, 1e3, -2e3}) * Transform::rotate({3, 1, 0}, -1.2),
        Transform::translate({-1e6, 3e5, 0}) * *Transform::from_affine(shear)};
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1, 1);
    int accepted = 0, rejected = 0;
    for (const Transform& xf : xfs)
        for (std::size_t i = 0; i < frame.cull_count(); ++i) {
            Capsule world;
            ASSERT_TRUE(frame.cull_capsule(i, xf, world));
            const FloatCapsule kept_in_float = FloatCapsule::holding(world);
            for (int n = 0; n < 3000; ++n) {
                // A line through a point at about the reach from the hook's axis (in the
                // lattice's space), many within rounding of the capsules' surfaces.
                const Vec3 d = normalize(Vec3{u(rng), u(rng), u(rng)});
                const Vec3 p{2 + 1.5 * u(rng), 1 + 1.5 * u(rng), 2 + 1.5 * u(rng)};
                const double far = n % 6 == 0 ? 1e13 : n % 3 == 0 ? 1e9 : 5.0;
                Ray local{p - d * far, d};
                if (n % 2 == 0) local = grazing(frame, i, xf, local);
                const Ray r{xf.point(local.o), xf.vector(local.d)};
                const bool kept = frame.cull_meets(i, xf.inverse_ray(r));
                const bool kept_world = world.meets_line(r.o, r.d);
                if (kept) {
                    ++accepted;
                    // The capsule in double, without FloatCapsule's allowance for far origins.
                    if (n % 3 != 0) {
                        ASSERT_TRUE(kept_world) << "part " << i << " line " << n;
                    }
                    ASSERT_TRUE(kept_in_float.meets_line(r.o, r.d)) << "part " << i << " line " << n;
                }
                rejected += kept_in_float.meets_line(r.o, r.d) ? 0 : 1;
            }
        }
    EXPECT_GT(accepted, 3000);
    EXPECT_GT(rejected, 3000);
}

}  // namespace
}  // namespace lat
