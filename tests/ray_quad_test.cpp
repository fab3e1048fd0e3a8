// geometry/ray_quad.h: four parallel rays tested at once give, lane by lane, the scalar tests'
// answers bit for bit: what was met, where (t), on which surface, and which rays are blocked,
// for spheres, flat-ended cylinders and chains of them, on rays that miss, graze, start inside,
// run along the axis or across it, and with ranges cut anywhere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "geometry/ray_quad.h"
#include "hook_primitive.h"

namespace lat {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

Vec3 random_unit(std::mt19937_64& rng) {
    std::normal_distribution<double> g;
    for (;;) {
        const Vec3 v{g(rng), g(rng), g(rng)};
        if (length(v) > 1e-3) return normalize(v);
    }
}

// Four rays of direction d through points around `target`: at random offsets across d, or
// (one time in three) at distance `graze` from the target with a relative error of 0 to 1e-9,
// so that some lanes are tangent within rounding. Ranges cut the rays anywhere.
RayQuad random_quad(std::mt19937_64& rng, Vec3 target, Vec3 d, double spread, double graze) {
    std::uniform_real_distribution<double> u(-1, 1);
    Vec3 a, b;
    orthonormal_basis(normalize(d), a, b);
    RayQuad q;
    q.d = d;
    for (int k = 0; k < 4; ++k) {
        const double angle = 3.2 * u(rng);
        const double dist = rng() % 3 == 0 ? graze * (1 + 1e-9 * double(rng() % 3) * u(rng))
                                           : spread * std::abs(u(rng));
        const Vec3 o = target + a * (dist * std::cos(angle)) + b * (dist * std::sin(angle)) -
                       d * (4 * u(rng));
        q.ox[k] = o.x, q.oy[k] = o.y, q.oz[k] = o.z;
        q.tmin[k] = rng() % 4 == 0 ? -kInfinity : 6 * u(rng);
        q.tmax[k] = rng() % 4 == 0 ? kInfinity : q.tmin[k] + 8 * std::abs(u(rng));
    }
    return q;
}

// Compares a shape's quad tests with its scalar ones on q, for every live mask.
template <class S>
void expect_lanes_are_scalar(const S& shape, const RayQuad& q0) {
    for (unsigned live = 0; live < 16; ++live) {
        RayQuad q = q0;
        QuadCrossings hits{};
        const unsigned found = shape.intersect_quad(q, live, hits);
        const unsigned blocked = shape.occluded_quad(q0, live);
        for (int k = 0; k < 4; ++k) {
            Crossing c;
            const bool live_k = live >> k & 1;
            const bool met = live_k && shape.intersect(q0.ray(k), q0.tmin[k], q0.tmax[k], c);
            ASSERT_EQ(bool(found >> k & 1), met) << "lane " << k << " live " << live;
            if (met) {
                EXPECT_TRUE(same_bits(hits.c[k].t, c.t)) << hits.c[k].t << " " << c.t;
                EXPECT_EQ(hits.c[k].part, c.part);
                EXPECT_TRUE(same_bits(q.tmax[k], c.t));  // the range narrowed to the crossing
            } else {
                EXPECT_TRUE(same_bits(q.tmax[k], q0.tmax[k]));
            }
            const bool occ = live_k && shape.occluded(q0.ray(k), q0.tmin[k], q0.tmax[k]);
            EXPECT_EQ(bool(blocked >> k & 1), occ) << "lane " << k << " live " << live;
        }
    }
}

TEST(RayQuad, SphereLanesAreTheScalarTests) {
    std::mt19937_64 rng(7);
    for (int n = 0; n < 3000; ++n) {
        const SphereShape s({0.3, -1.2, 2.0}, 0.25 + 0.001 * double(n % 500));
        Vec3 d = random_unit(rng) * (0.5 + 0.001 * double(n % 1000));
        if (n % 10 == 0) d = {0, 0, 1};  // along an axis
        expect_lanes_are_scalar(s, random_quad(rng, s.center(), d, 2 * s.radius(), s.radius()));
    }
}

TEST(RayQuad, CylinderLanesAreTheScalarTests) {
    std::mt19937_64 rng(11);
    const Vec3 a{1, 1, 1}, b{1.5, 2.5, 3.0};
    const double radius = 0.4;
    const CappedCylinderShape cyl(a, b, radius);
    const Vec3 axis = normalize(b - a);
    Vec3 across, other;
    orthonormal_basis(axis, across, other);
    for (int n = 0; n < 6000; ++n) {
        Vec3 d = random_unit(rng);
        if (n % 6 == 1) d = axis * 0.7;     // along the axis: no side crossing, ends only
        if (n % 6 == 2) d = across * 1.3;   // across it: no end crossing, the side only
        if (n % 6 == 3) d = {0, 1, 0};      // along a world axis
        const Vec3 target = lerp(a, b, double(n % 7) / 6.0);
        expect_lanes_are_scalar(cyl, random_quad(rng, target, d, 3 * radius, radius));
    }
}

// The branches random rays never take: directions with components exactly 0 (an end cap's
// slab or the side's quadratic absent), no direction at all, a ray starting on a sphere where
// it is tangent (both roots 0), ranges ending exactly at a crossing, and NaN ranges.
TEST(RayQuad, EdgeCasesAreTheScalarTests) {
    const CappedCylinderShape along_z({1, 1, 0}, {1, 1, 2}, 0.5);
    const SphereShape ball({0, 0, 0}, 1);
    const auto quad = [](Vec3 o, Vec3 step, Vec3 d) {
        RayQuad q;
        q.d = d;
        for (int k = 0; k < 4; ++k) {
            q.ox[k] = o.x + step.x * k, q.oy[k] = o.y + step.y * k, q.oz[k] = o.z + step.z * k;
            q.tmin[k] = k == 3 ? -kInfinity : 0, q.tmax[k] = kInfinity;
        }
        return q;
    };
    // Across the axis (da = 0), along it (A = 0), none.
    for (const Vec3 d : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -2}, Vec3{}}) {
        expect_lanes_are_scalar(along_z, quad({-1, 0.6, 1}, {0, 0.25, 0.3}, d));
        expect_lanes_are_scalar(along_z, quad({1.2, 0.9, -1}, {0.1, 0.1, 1.0}, d));
        expect_lanes_are_scalar(ball, quad({-2, -0.5, 0}, {0, 0.5, 0}, d));
    }
    // Starting where tangent: the closest point is the origin, on the surface.
    expect_lanes_are_scalar(ball, quad({0, 1, 0}, {0, 0, 0}, {1, 0, 0}));
    expect_lanes_are_scalar(along_z, quad({1.5, 1, 1}, {0, 0, 0.2}, {0, 1, 0}));
    // Ranges that end or start exactly at the scalar test's crossings, and NaN ones.
    for (const Vec3 d : {Vec3{1, 0.1, 0.05}, Vec3{0, 0, 1}}) {
        RayQuad q = quad({-3, 0.2, -3 * d.z}, {0, 0.1, 0}, d);
        for (int k = 0; k < 4; ++k) {
            double t0, t1;
            if (!ball.solve(q.ray(k), t0, t1)) continue;
            if (k == 0) q.tmax[k] = t0;
            if (k == 1) q.tmin[k] = t0;
            if (k == 2) q.tmin[k] = t0, q.tmax[k] = t1;
            if (k == 3) q.tmin[k] = std::nan("");
        }
        expect_lanes_are_scalar(ball, q);
        Crossing in, out;
        RayQuad c = quad({-2, 1.2, -1}, {0, -0.1, 0.2}, d);
        for (int k = 0; k < 4; ++k) {
            if (!along_z.solve(c.ray(k), in, out)) continue;
            if (k == 0) c.tmax[k] = in.t;
            if (k == 1) c.tmin[k] = in.t;
            if (k == 2) c.tmin[k] = in.t, c.tmax[k] = out.t;
            if (k == 3) c.tmax[k] = std::nan("");
        }
        expect_lanes_are_scalar(along_z, c);
    }
}

TEST(RayQuad, ChainLanesAreTheScalarLoopsOverParts) {
    const ChainShape& hook = test::hook();
    std::mt19937_64 rng(3);
    const Bounds3 box = hook.bounds();
    for (int n = 0; n < 4000; ++n) {
        // Any order of any parts: ties go to the earlier listed part in both.
        std::vector<std::uint32_t> parts;
        for (std::uint32_t i = 0; i < hook.part_count(); ++i)
            if (rng() % 3 != 0) parts.push_back(i);
        std::shuffle(parts.begin(), parts.end(), rng);
        const Vec3 target = lerp(box.lo, box.hi, 0.5 + 0.3 * (double(rng() % 101) / 50 - 1));
        const RayQuad q0 = random_quad(rng, target, random_unit(rng), 1.5, 0.5);
        for (unsigned live : {15u, 5u, 8u}) {
            RayQuad q = q0;
            QuadCrossings hits{};
            const unsigned found = hook.first_crossings(parts, q, live, hits);
            const unsigned blocked = hook.blocked_lanes(parts, q0, live);
            for (int k = 0; k < 4; ++k) {
                const bool live_k = live >> k & 1;
                Crossing c;
                const bool met = live_k && first_crossing_of_parts(hook, parts, q0.ray(k),
                                                                   q0.tmin[k], q0.tmax[k], c);
                ASSERT_EQ(bool(found >> k & 1), met);
                if (met) {
                    EXPECT_TRUE(same_bits(hits.c[k].t, c.t));
                    EXPECT_EQ(hits.c[k].part, c.part);
                    EXPECT_TRUE(same_bits(q.tmax[k], c.t));  // narrowed, as the scalar loop does
                }
                const bool occ =
                    live_k && any_part_occludes(hook, parts, q0.ray(k), q0.tmin[k], q0.tmax[k]);
                EXPECT_EQ(bool(blocked >> k & 1), occ);
            }
        }
    }
}

}  // namespace
}  // namespace lat
