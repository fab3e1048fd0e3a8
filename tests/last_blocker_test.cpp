// Shadow rays that test first what blocked the last ray of their run (EmbreeAccel::LastBlocker):
// the same answers as without it, whatever blocks (a sphere placed whole, a chain's part placed
// flat or through an Embree instance, the ray's own object), and what was tested first is not
// tested again by the traversal.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "accel/embree_accel.h"
#include "geometry/chain.h"
#include "counted_sphere.h"

namespace lat {
namespace {

using test::CountedSphere;

const Transform kIdentity;

TEST(LastBlocker, WhatBlockedTheLastRayIsTestedFirstAndOnce) {
    CountedSphere front({0, 0, 5}, 1), back({0, 0, 8}, 1);
    const std::vector<AccelObject> objects{{&front, &kIdentity}, {&back, &kIdentity}};
    const EmbreeAccel accel(objects);
    const Ray up{{0, 0, 0}, {0, 0, 1}};
    EmbreeAccel::LastBlocker last;

    // Only the front sphere in range (the any-hit traversal may meet either first).
    ASSERT_TRUE(accel.occluded(up, 0, 6.5, EmbreeAccel::kNoObject, &last));
    EXPECT_NE(last.object, EmbreeAccel::kNoObject);
    EXPECT_EQ(last.part, EmbreeAccel::kWhole);

    // Blocked again by the front sphere, tested first: the traversal does not run.
    front.tests = back.tests = 0;
    EXPECT_TRUE(accel.occluded(up, 0, 20, EmbreeAccel::kNoObject, &last));
    EXPECT_EQ(front.tests, 1);
    EXPECT_EQ(back.tests, 0);

    // Through both spheres' boxes, missing both: the front one tested first, and only then.
    // The run's blocker is then forgotten: the next ray does not test it first.
    const Ray corner{{0.95, 0.95, 0}, {0, 0, 1}};
    front.tests = back.tests = 0;
    EXPECT_FALSE(accel.occluded(corner, 0, 20, EmbreeAccel::kNoObject, &last));
    EXPECT_EQ(front.tests, 1);
    EXPECT_EQ(back.tests, 1);
    EXPECT_EQ(last.object, EmbreeAccel::kNoObject);

    // The back sphere blocks a ray that starts past the front one: it becomes the one kept.
    ASSERT_TRUE(accel.occluded({{0, 0, 6.5}, {0, 0, 1}}, 0, 20, EmbreeAccel::kNoObject, &last));
    front.tests = back.tests = 0;
    EXPECT_TRUE(accel.occluded(up, 7.5, 20, EmbreeAccel::kNoObject, &last));
    EXPECT_EQ(back.tests, 1);
    EXPECT_EQ(front.tests, 0);
}

// A ray Embree cannot trace (its origin lies past 1.8e18) meets unbounded objects alone, with
// or without a kept blocker that its line crosses.
TEST(LastBlocker, ARayEmbreeCannotTraceMeetsUnboundedObjectsAlone) {
    CountedSphere huge({0, 0, 0}, 1e18);
    const std::vector<AccelObject> objects{{&huge, &kIdentity}};
    const EmbreeAccel accel(objects);
    EmbreeAccel::LastBlocker last;
    const Ray near{{0, 0, -1.5e18}, {0, 0, 1}};
    ASSERT_TRUE(accel.occluded(near, 0, 1e19, EmbreeAccel::kNoObject, &last));
    ASSERT_NE(last.object, EmbreeAccel::kNoObject);
    const Ray far{{0, 0, -4e18}, {0, 0, 1}};
    const bool alone = accel.occluded(far, 2e18, 1e19);
    huge.tests = 0;
    EXPECT_EQ(accel.occluded(far, 2e18, 1e19, EmbreeAccel::kNoObject, &last), alone);
    EXPECT_EQ(huge.tests, 0);
}

// Rays up through a row of spheres, each blocked by its own: the kept blocker is tested first
// in vain while trusted, then no longer, until it blocks a ray again.
TEST(LastBlocker, ABlockerTestedInVainIsNoLongerTestedFirst) {
    std::vector<std::unique_ptr<CountedSphere>> row;
    std::vector<AccelObject> objects;
    for (int i = 0; i < 6; ++i) {
        row.push_back(std::make_unique<CountedSphere>(Vec3{2.0 * i, 0, 5}, 0.5));
        objects.push_back({row.back().get(), &kIdentity});
    }
    const EmbreeAccel accel(objects);
    EmbreeAccel::LastBlocker last;
    const auto up_through = [&](int i) {
        for (auto& s : row) s->tests = 0;
        return accel.occluded({{2.0 * i, 0, 0}, {0, 0, 1}}, 0, 20, EmbreeAccel::kNoObject, &last);
    };
    ASSERT_TRUE(up_through(0));
    for (int i = 1; i <= EmbreeAccel::kMaxTrust; ++i) {
        ASSERT_TRUE(up_through(i));
        EXPECT_EQ(row[static_cast<std::size_t>(i - 1)]->tests, 1) << i;  // tested first, in vain
    }
    EXPECT_EQ(last.trust, 0);
    const std::size_t kept = EmbreeAccel::kMaxTrust;
    ASSERT_TRUE(up_through(kept + 1));
    EXPECT_EQ(row[kept]->tests, 0);  // no longer tested first
    // Blocking the next ray without being tested first, it is trusted again.
    ASSERT_TRUE(up_through(kept + 1));
    EXPECT_EQ(last.trust, EmbreeAccel::kMaxTrust);
    ASSERT_TRUE(up_through(kept + 1));
    EXPECT_EQ(row[kept + 1]->tests, 1);
}

// Shadow rays in runs, as a tile's pixels cast them toward two lights, through spheres, wavy
// chains (placed turned and moved) and a floor: the same answers with and without the blocker
// kept, with chains placed flat and as Embree instances; fewer sphere tests with it.
struct Crowd {
    std::vector<std::unique_ptr<CountedSphere>> spheres;
    ChainShape chain;
    std::vector<Transform> xf;
    std::vector<AccelObject> objects;

    Crowd() : chain(make_chain()) {
        std::mt19937 rng(11);
        std::uniform_real_distribution<double> u(-4, 4), rad(0.2, 0.7), angle(0, 6.28);
        xf.reserve(60);  // AccelObject keeps pointers into xf
        for (int i = 0; i < 30; ++i) {
            const Vec3 c{u(rng), u(rng), u(rng) + 5};
            spheres.push_back(std::make_unique<CountedSphere>(c, rad(rng)));
            objects.push_back({spheres.back().get(), &kIdentity});
        }
        for (int i = 0; i < 20; ++i) {
            xf.push_back(Transform::translate({u(rng), u(rng), u(rng) + 5}) *
                         Transform::rotate({1, 0.3, 0.2}, angle(rng)));
            objects.push_back({&chain, &xf.back()});
        }
    }
    static ChainShape make_chain() {
        std::vector<ChainSphere> s;
        std::vector<ChainCylinder> c;
        for (int k = 0; k < 8; ++k) {
            s.push_back({{0.3 * std::sin(k), 0.3 * std::cos(k), 0.4 * k}, 0.12});
            if (k) c.push_back({k - 1, k, 0.12});
        }
        return ChainShape(s, c);
    }
    int sphere_tests() const {
        int n = 0;
        for (const auto& s : spheres) n += s->tests;
        return n;
    }
};

TEST(LastBlocker, RunsOfShadowRaysAnswerAsWithoutIt) {
    for (const Instancing inst : {Instancing::kNever, Instancing::kAlways}) {
        Crowd crowd;
        const EmbreeAccel accel(crowd.objects, {.instancing = inst});
        const Vec3 lights[2] = {{30, -20, 40}, {-25, 10, 30}};
        EmbreeAccel::LastBlocker last[2];
        int blocked = 0, with_tests = 0, without_tests = 0;
        std::mt19937 rng(5);
        std::uniform_int_distribution<std::uint32_t> self(0, 60);  // past 49: none
        for (int j = 0; j < 60; ++j)
            for (int i = 0; i < 60; ++i) {
                // A tile's points, row by row, on a plane below the crowd.
                const Vec3 p{-5 + i / 6.0, -5 + j / 6.0, 0.5 + 0.05 * ((i * j) % 7)};
                const std::uint32_t s = self(rng);
                for (int l = 0; l < 2; ++l) {
                    const Vec3 to = lights[l] - p;
                    const Ray r{p, normalize(to)};
                    const double tmax = length(to);
                    const int before = crowd.sphere_tests();
                    const bool plain = accel.occluded(r, 1e-6, tmax, s);
                    const int mid = crowd.sphere_tests();
                    const bool kept = accel.occluded(r, 1e-6, tmax, s, &last[l]);
                    without_tests += mid - before;
                    with_tests += crowd.sphere_tests() - mid;
                    ASSERT_EQ(kept, plain) << "point " << i << ", " << j << ", light " << l;
                    blocked += plain;
                }
            }
        EXPECT_GT(blocked, 1000);  // the runs have blockers to keep
        EXPECT_LT(blocked, 6000);  // and rays that pass
        EXPECT_LT(with_tests, without_tests);
    }
}

}  // namespace
}  // namespace lat
