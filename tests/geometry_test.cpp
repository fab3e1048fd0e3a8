// Leaf shapes against closed-form answers: spheres, flat-ended cylinders, chains, half-spaces.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "geometry/algebraic.h"
#include "geometry/capped_cylinder.h"
#include "geometry/chain.h"
#include "geometry/halfspace.h"
#include "geometry/lattice_source.h"
#include "geometry/named_shapes.h"
#include "geometry/sphere.h"
#include "math/transform.h"

namespace lat {
namespace {

TEST(Sphere, HitsFromOutsideAndInside) {
    SphereShape s({1, 2, 3}, 2);
    Crossing c;
    ASSERT_TRUE(s.intersect({{1, 2, -10}, {0, 0, 1}}, 0, kInfinity, c));
    EXPECT_DOUBLE_EQ(c.t, 11);
    EXPECT_NEAR(length(s.normal({{1, 2, -10}, {0, 0, 1}}, c) - Vec3{0, 0, -1}), 0, 1e-15);
    ASSERT_TRUE(s.intersect({{1, 2, 3}, {0, 0, 2}}, 0, kInfinity, c));  // from the centre
    EXPECT_DOUBLE_EQ(c.t, 1);
    EXPECT_FALSE(s.intersect({{1, 2, -10}, {0, 0, 1}}, 0, 10, c));
    EXPECT_FALSE(s.intersect({{3.0001, 2, -10}, {0, 0, 1}}, 0, kInfinity, c));
}

TEST(Sphere, FarAwayRayIsAccurate) {
    // From 1e6 away the naive quadratic loses ~6 digits; the stable form must not.
    SphereShape s({0, 0, 0}, 1);
    const Ray r{{0.5, 0, -1e6}, {0, 0, 1}};
    Crossing c;
    ASSERT_TRUE(s.intersect(r, 0, kInfinity, c));
    EXPECT_NEAR(c.t, 1e6 - std::sqrt(0.75), 1e-9);
}

TEST(Sphere, SpansCoverTheChord) {
    SphereShape s({0, 0, 0}, 1);
    SpanList spans;
    s.spans({{-5, 0, 0}, {1, 0, 0}}, spans);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_DOUBLE_EQ(spans[0].in.t, 4);
    EXPECT_DOUBLE_EQ(spans[0].out.t, 6);
}

TEST(HalfSpace, SpansAndHits) {
    HalfSpaceShape h({0, 0, 1}, {0, 0, 2});
    SpanList spans;
    h.spans({{0, 0, 5}, {0, 0, -1}}, spans);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_DOUBLE_EQ(spans[0].in.t, 4);
    EXPECT_EQ(spans[0].out.t, kInfinity);
    spans.clear();
    h.spans({{0, 0, 0}, {1, 0, 0}}, spans);  // parallel, inside
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].in.t, -kInfinity);
    spans.clear();
    h.spans({{0, 0, 2}, {1, 0, 0}}, spans);  // parallel, outside
    EXPECT_TRUE(spans.empty());
    Crossing c;
    EXPECT_TRUE(h.intersect({{0, 0, 5}, {0, 0, -1}}, 0, kInfinity, c));
    EXPECT_DOUBLE_EQ(c.t, 4);
    EXPECT_FALSE(h.intersect({{0, 0, 5}, {0, 0, 1}}, 0, kInfinity, c));
}

TEST(CappedCylinder, SideAndEnds) {
    CappedCylinderShape cyl({0, 0, 0}, {0, 0, 10}, 1);
    Crossing c;
    // Side hit.
    ASSERT_TRUE(cyl.intersect({{-5, 0, 5}, {1, 0, 0}}, 0, kInfinity, c));
    EXPECT_DOUBLE_EQ(c.t, 4);
    EXPECT_EQ(c.part, 0u);
    EXPECT_NEAR(length(cyl.normal({{-5, 0, 5}, {1, 0, 0}}, c) - Vec3{-1, 0, 0}), 0, 1e-15);
    // End hits, both ends, with axis normals.
    ASSERT_TRUE(cyl.intersect({{0.5, 0, -3}, {0, 0, 1}}, 0, kInfinity, c));
    EXPECT_DOUBLE_EQ(c.t, 3);
    EXPECT_EQ(c.part, 1u);
    EXPECT_EQ(cyl.normal({{0.5, 0, -3}, {0, 0, 1}}, c), (Vec3{0, 0, -1}));
    ASSERT_TRUE(cyl.intersect({{0.5, 0, 13}, {0, 0, -1}}, 0, kInfinity, c));
    EXPECT_DOUBLE_EQ(c.t, 3);
    EXPECT_EQ(c.part, 2u);
    // Misses past the ends (flat ends, no caps).
    EXPECT_FALSE(cyl.intersect({{-5, 0, 10.5}, {1, 0, 0}}, 0, kInfinity, c));
    EXPECT_FALSE(cyl.intersect({{1.01, 0, -3}, {0, 0, 1}}, 0, kInfinity, c));
}

TEST(CappedCylinder, BoundsAreTight) {
    CappedCylinderShape cyl({0, 0, 0}, {3, 4, 0}, 1);
    const Bounds3 b = cyl.bounds();
    EXPECT_NEAR(b.lo.x, -0.8, 1e-12);
    EXPECT_NEAR(b.hi.y, 4.6, 1e-12);
    EXPECT_NEAR(b.hi.z, 1.0, 1e-12);
}

TEST(CappedCylinder, MatchesInsideTestOnRandomRays) {
    // Every reported span's midpoint is inside, points just outside spans are outside.
    CappedCylinderShape cyl({1, -1, 0.5}, {-2, 3, 4}, 0.7);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-6, 6);
    int spans_seen = 0;
    for (int n = 0; n < 20000; ++n) {
        const Ray r{{u(rng), u(rng), u(rng)}, normalize(Vec3{u(rng), u(rng), u(rng)})};
        SpanList spans;
        cyl.spans(r, spans);
        for (const Span& s : spans) {
            ++spans_seen;
            EXPECT_TRUE(cyl.inside(r.at(0.5 * (s.in.t + s.out.t))));
            EXPECT_FALSE(cyl.inside(r.at(s.in.t - 1e-6)));
            EXPECT_FALSE(cyl.inside(r.at(s.out.t + 1e-6)));
        }
        if (spans.empty()) {
            // Sample the line: no point may be inside.
            for (double t = -20; t <= 20; t += 0.05) ASSERT_FALSE(cyl.inside(r.at(t)));
        }
    }
    EXPECT_GT(spans_seen, 1000);
}

TEST(Chain, UnionOfPartsMergesSpans) {
    // Two spheres joined by a cylinder: a capsule along z from 0 to 4, radius 1.
    ChainShape chain({{{0, 0, 0}, 1}, {{0, 0, 4}, 1}}, {{0, 1, 1}});
    SpanList spans;
    chain.spans({{0, 0, -10}, {0, 0, 1}}, spans);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_DOUBLE_EQ(spans[0].in.t, 9);
    EXPECT_DOUBLE_EQ(spans[0].out.t, 15);
    Crossing c;
    ASSERT_TRUE(chain.intersect({{-10, 0, 2}, {1, 0, 0}}, 0, kInfinity, c));
    EXPECT_DOUBLE_EQ(c.t, 9);
    EXPECT_EQ(c.part >> 2, 2u);  // the cylinder, numbered after the two spheres
    EXPECT_NEAR(length(chain.normal({{-10, 0, 2}, {1, 0, 0}}, c) - Vec3{-1, 0, 0}), 0, 1e-15);
    EXPECT_EQ(chain.part_count(), 3u);
    EXPECT_TRUE(chain.inside({0, 0, 4.9}));
    EXPECT_FALSE(chain.inside({0.9, 0, 4.9}));
    // Its pieces (exact lattices) are its parts, and it is their union: the top sphere alone
    // is the span from 3 to 5, all three the capsule.
    EXPECT_TRUE(ShapeSource(chain).pieces_are_union());
    const Ray up{{0, 0, -10}, {0, 0, 1}};
    const std::uint32_t top[] = {1}, all[] = {0, 1, 2};
    SpanList one, three;
    ShapeSource(chain).pieces_spans(top, up, one);
    ShapeSource(chain).pieces_spans(all, up, three);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_DOUBLE_EQ(one[0].in.t, 13);
    EXPECT_DOUBLE_EQ(one[0].out.t, 15);
    ASSERT_EQ(three.size(), 1u);
    EXPECT_DOUBLE_EQ(three[0].in.t, 9);
    EXPECT_DOUBLE_EQ(three[0].out.t, 15);
}

TEST(Transform, InverseAndNormals) {
    const Transform t = Transform::translate({1, 2, 3}) * Transform::rotate({0, 0, 1}, 0.3) *
                        Transform::scale({2, 1, 0.5});
    const Vec3 p{0.3, -0.7, 1.1};
    EXPECT_NEAR(length(t.inverse_point(t.point(p)) - p), 0, 1e-14);
    // A normal stays perpendicular to a transformed tangent.
    const Vec3 n{0, 0, 1}, tangent{1, 1, 0};
    EXPECT_NEAR(dot(t.normal(n), t.vector(tangent)), 0, 1e-14);
    EXPECT_FALSE(Transform::from_affine({Mat3::diagonal({1, 0, 1}), {}}).has_value());
}


// Capsules cull lattices: meets_line must agree with the distance from the line to points
// along the segment, and a chain's capsules must hold its parts.
TEST(Capsule, MeetsLineAgreesWithSampledDistance) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-3, 3);
    int met = 0, missed = 0;
    for (int k = 0; k < 2000; ++k) {
        const Capsule c{{u(rng), u(rng), u(rng)}, k % 5 == 0 ? Vec3{} : Vec3{u(rng), u(rng), u(rng)},
                        0.2 + 0.3 * std::abs(u(rng))};
        // Lines aimed near the capsule, so that about half of them meet it.
        const Vec3 o{u(rng) * 10, u(rng) * 10, u(rng) * 10};
        const Vec3 aim = lerp(c.a, c.b, (u(rng) + 3) / 6) + Vec3{u(rng), u(rng), u(rng)} * 0.3;
        const Vec3 d = aim - o;
        double best = kInfinity;
        for (int s = 0; s <= 4000; ++s) {
            const Vec3 p = lerp(c.a, c.b, s / 4000.0), w = p - o;
            best = std::min(best, length_squared(w - d * (dot(w, d) / dot(d, d))));
        }
        const double dist = std::sqrt(best);
        if (std::abs(dist - c.r) < 1e-2) continue;  // too close to call by sampling
        EXPECT_EQ(c.meets_line(o, d), dist < c.r) << k;
        (dist < c.r ? met : missed)++;
    }
    EXPECT_GT(met, 100);
    EXPECT_GT(missed, 100);
}

TEST(Capsule, ChainCapsulesHoldTheirPartsAndJointSpheresAreContained) {
    const std::vector<ChainSphere> spheres{{{0, 0, 0}, 0.5}, {{1, 2, 3}, 0.5}, {{2, 2, 5}, 0.4}};
    const std::vector<ChainCylinder> cylinders{{0, 1, 0.5}, {1, 2, 0.4}};
    const ChainShape chain(spheres, cylinders);
    std::vector<std::unique_ptr<Shape>> parts;  // the chain's parts, in its order
    for (const ChainSphere& s : spheres) parts.push_back(std::make_unique<SphereShape>(s.center, s.radius));
    for (const ChainCylinder& c : cylinders)
        parts.push_back(std::make_unique<CappedCylinderShape>(
            spheres[static_cast<std::size_t>(c.from)].center,
            spheres[static_cast<std::size_t>(c.to)].center, c.radius));
    ASSERT_EQ(parts.size(), chain.part_count());
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 6);
    for (std::size_t i = 0; i < chain.part_count(); ++i) {
        Capsule c;
        ASSERT_TRUE(chain.part_capsule(i, c));
        int inside = 0;
        for (int k = 0; k < 20000; ++k) {
            const Vec3 p{u(rng), u(rng), u(rng)};
            if (!parts[i]->inside(p)) continue;
            ++inside;
            EXPECT_LE(c.distance_squared(p), c.r * c.r * (1 + 1e-12)) << i;
        }
        EXPECT_GT(inside, 5) << i;
    }
    Capsule joint, cyl, thin;
    chain.part_capsule(1, joint);  // the sphere at (1, 2, 3), radius 0.5
    chain.part_capsule(3, cyl);    // the cylinder from sphere 0 to sphere 1, radius 0.5
    chain.part_capsule(4, thin);   // radius 0.4: cannot hold the 0.5 sphere
    EXPECT_TRUE(cyl.contains(joint));
    EXPECT_FALSE(thin.contains(joint));
    EXPECT_TRUE(joint.contains(joint));
}

// A placed torus is bounded by its exact extent (ring + ball support), under rotations and
// non-uniform scales: it holds every surface point and is touched by them on every side.
TEST(Torus, PlacedBoundsAreExact) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int k = 0; k < 20; ++k) {
        const PlacedShape t = make_torus({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng) + 1.5},
                                         3.0, 0.35);
        const Transform user = Transform::translate({u(rng), u(rng), u(rng)}) *
                               Transform::rotate({u(rng), u(rng), 1.0}, 3 * u(rng)) *
                               Transform::scale({1.2 + u(rng), 1.2 + u(rng), 1.2 + u(rng)});
        const Transform xf = user * t.placement;
        const Bounds3 b = t.shape->placed_bounds(xf);
        Bounds3 seen;
        for (int i = 0; i < 400; ++i)
            for (int j = 0; j < 100; ++j) {
                const double a = 2 * M_PI * i / 400, v = 2 * M_PI * j / 100;
                const double ring = 3.0 + 0.35 * std::cos(v);
                const Vec3 p = xf.point({ring * std::cos(a), ring * std::sin(a), 0.35 * std::sin(v)});
                seen = merge(seen, Bounds3{p, p});
            }
        const double scale = max_component(b.extent());
        for (std::size_t axis = 0; axis < 3; ++axis) {
            EXPECT_LE(b.lo[axis], seen.lo[axis] + 1e-9) << k;
            EXPECT_GE(b.hi[axis], seen.hi[axis] - 1e-9) << k;
            EXPECT_NEAR(b.lo[axis], seen.lo[axis], 2e-3 * scale) << k;
            EXPECT_NEAR(b.hi[axis], seen.hi[axis], 2e-3 * scale) << k;
        }
    }
}

// A torus's solid within ball of its ring: the ring test in line_roots (rays that keep out of
// the slab-and-annulus around the ring cost no quartic) must lose no root. The same polynomial
// and box without the extent is the reference, on lines aimed near the tube, through the hole,
// grazing it and from far away.
TEST(Torus, RingTestLosesNoRoot) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (const auto& [major, minor] : {std::pair{3.0, 0.35}, {1.0, 0.6}, {0.5, 0.5}, {2.0, 0.01}}) {
        const PlacedShape t = make_torus({0, 0, 0}, {0, 0, 1}, major, minor);
        const auto& ring = dynamic_cast<const AlgebraicShape&>(*t.shape);
        const AlgebraicShape plain(ring.polynomial(), ring.bounds(), {0, 0, 0});
        int crossings = 0;
        for (int n = 0; n < 20000; ++n) {
            const double a = M_PI * u(rng), reach = major + minor * (1.2 * u(rng));
            const Vec3 target{reach * std::cos(a), reach * std::sin(a), 1.2 * minor * u(rng)};
            const Vec3 d = normalize(Vec3{u(rng), u(rng), n % 3 == 0 ? 0.0 : u(rng)});
            const double back = n % 7 == 0 ? 1e4 : 3 * (major + minor);
            const Ray r{target - d * back, d};
            SpanList a1, a2;
            ring.spans(r, a1);
            plain.spans(r, a2);
            ASSERT_EQ(a1.size(), a2.size()) << n;
            for (std::size_t k = 0; k < a1.size(); ++k) {
                ASSERT_EQ(a1[k].in.t, a2[k].in.t) << n;
                ASSERT_EQ(a1[k].out.t, a2[k].out.t) << n;
            }
            crossings += static_cast<int>(a1.size());
        }
        EXPECT_GT(crossings, 5000) << major;
    }
}

// The ring of spheres a torus gives for culling (lattice rasterization, candidates) holds the
// whole solid, and is much tighter than the sphere around its box.
TEST(Torus, RingSpheresHoldTheSolid) {
    for (const auto& [major, minor] : {std::pair{3.0, 0.35}, {1.0, 0.6}, {2.0, 0.01}}) {
        const PlacedShape t = make_torus({0, 0, 0}, {0, 0, 1}, major, minor);
        std::vector<BoundingSphere> spheres;
        ShapeParts(*t.shape).part_spheres(0, spheres);
        double volume = 0;
        for (const BoundingSphere& s : spheres) volume += 4.0 / 3 * M_PI * std::pow(s.radius, 3);
        const double box = std::pow(0.5 * length(t.shape->bounds().extent()), 3) * 4.0 / 3 * M_PI;
        EXPECT_LT(volume, (minor < 0.2 * major ? 0.1 : 1.0) * box) << major;
        for (int i = 0; i < 720; ++i)
            for (int j = 0; j < 36; ++j) {
                const double a = 2 * M_PI * i / 720, v = 2 * M_PI * j / 36;
                const double w = major + minor * std::cos(v);
                const Vec3 p{w * std::cos(a), w * std::sin(a), minor * std::sin(v)};
                bool held = false;
                for (const BoundingSphere& s : spheres)
                    held = held || length(p - s.center) <= s.radius;
                ASSERT_TRUE(held) << major << " " << i << " " << j;
            }
    }
}

}  // namespace
}  // namespace lat

namespace lat {
namespace {

// Poly3::along_ray unrolls its terms at compile time; it must give, bit for bit, the loop over
// the terms it replaced (images stayed the same), and the restriction itself must be right:
// c(t) = f(o + t d) at sample points.
TEST(Poly3, AlongRayIsTheLoopOverTermsBitForBit) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-2, 2);
    for (int n = 0; n < 500; ++n) {
        Poly3 f;
        for (double& a : f.a) a = n % 3 == 0 && u(rng) < 0 ? 0.0 : u(rng);  // some terms absent
        const Vec3 o{u(rng), u(rng), u(rng)}, d{u(rng), u(rng), u(rng)};
        double c[5];
        f.along_ray(o, d, c);
        // The loop, as it was written.
        double px[5][5] = {}, py[5][5] = {}, pz[5][5] = {};
        const auto powers = [](double oo, double dd, double p[5][5]) {
            p[0][0] = 1.0;
            for (int m = 1; m <= 4; ++m)
                for (int k = 0; k <= m; ++k)
                    p[m][k] = oo * p[m - 1][k] + (k > 0 ? dd * p[m - 1][k - 1] : 0.0);
        };
        powers(o.x, d.x, px);
        powers(o.y, d.y, py);
        powers(o.z, d.z, pz);
        double want[5] = {0, 0, 0, 0, 0};
        for (int t = 0; t < Poly3::kTerms; ++t) {
            const double coef = f.a[static_cast<std::size_t>(t)];
            if (coef == 0.0) continue;
            const auto [i, j, k] = Poly3::exponents(t);
            double xy[5] = {0, 0, 0, 0, 0};
            for (int a = 0; a <= i; ++a)
                for (int b = 0; b <= j; ++b) xy[a + b] += px[i][a] * py[j][b];
            for (int ab = 0; ab <= i + j; ++ab)
                for (int w = 0; w <= k; ++w) want[ab + w] += coef * xy[ab] * pz[k][w];
        }
        for (int m = 0; m < 5; ++m) ASSERT_EQ(c[m], want[m]) << "polynomial " << n << " c" << m;
        for (const double t : {-1.5, 0.25, 2.0}) {
            const double at = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * c[4])));
            EXPECT_NEAR(at, f.eval(o + d * t), 1e-9 * (1 + std::abs(at))) << n;
        }
    }
}

}  // namespace
}  // namespace lat
