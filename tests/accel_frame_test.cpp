// The accelerator culls as tightly far from the world's origin as at it: Embree's float side
// works in a frame centred on the scene (EmbreeAccel::Impl::frame), so the margin its boxes are
// grown by goes with the scene's size, not with its distance from the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "accel/embree_accel.h"
#include "geometry/chain.h"
#include "geometry/parts.h"
#include "counted_sphere.h"

namespace lat {
namespace {

using test::CountedSphere;

const Transform kIdentity;
constexpr int kSide = 10;          // spheres a side, one unit apart
constexpr double kRadius = 0.05;  // a hair's width, as a fur's instances are

// Rays down the gaps of a kSide x kSide grid of small spheres whose corner is at `corner`, and
// rays onto each sphere: the spheres tested by the gaps' rays, and whether every sphere's own
// ray met it where it should.
struct GridRun {
    int gap_tests = 0;
    bool hits_right = true;
};
GridRun run_grid(Vec3 corner) {
    std::vector<CountedSphere> spheres;
    spheres.reserve(kSide * kSide);
    for (int i = 0; i < kSide; ++i)
        for (int j = 0; j < kSide; ++j) spheres.emplace_back(corner + Vec3{1.0 * i, 1.0 * j, 0}, kRadius);
    std::vector<AccelObject> objects;
    for (const CountedSphere& s : spheres) objects.push_back({&s, &kIdentity});
    const EmbreeAccel accel(objects);

    GridRun run;
    for (int i = 0; i < kSide; ++i)
        for (int j = 0; j < kSide; ++j) {
            // Half a unit from every sphere's centre: far outside their boxes.
            const Ray gap{corner + Vec3{i + 0.5, j + 0.5, -10}, {0, 0, 1}};
            AccelHit hit;
            run.hits_right &= !accel.intersect(gap, 0, kInfinity, hit);
            run.hits_right &= !accel.occluded(gap, 0, kInfinity, EmbreeAccel::kNoObject, nullptr);
        }
    for (const CountedSphere& s : spheres) run.gap_tests += s.tests;
    for (int k = 0; k < kSide * kSide; ++k) {
        const Vec3 c = corner + Vec3{1.0 * (k / kSide), 1.0 * (k % kSide), 0};
        const Ray onto{c + Vec3{0, 0, -10}, {0, 0, 1}};
        AccelHit hit;
        run.hits_right &= accel.intersect(onto, 0, kInfinity, hit) &&
                          hit.object == static_cast<std::uint32_t>(k) &&
                          std::abs(hit.t - (10 - kRadius)) < 1e-9;
    }
    return run;
}

TEST(AccelFrame, FarFromTheOriginRaysInTheGapsTestNothing) {
    for (const Vec3 corner : {Vec3{0, 0, 0}, Vec3{1e6, 1e6, 0}, Vec3{-3e7, 2e7, 5e6}}) {
        const GridRun run = run_grid(corner);
        EXPECT_EQ(run.gap_tests, 0) << "grid at " << corner.x << ", " << corner.y << ", "
                                    << corner.z;
        EXPECT_TRUE(run.hits_right) << "grid at " << corner.x << ", " << corner.y << ", "
                                    << corner.z;
    }
}

// Thin chains (a hair: spheres joined by cylinders) placed far from the origin, turned and
// moved: rays through and around them answer alike whether the chains enter Embree as
// instances of one prototype (a float transform a ray is carried through) or part by part in
// world space. Far out, the instances' float transforms once lost a grazing ray's crossings.
TEST(AccelFrame, FarFromTheOriginInstancesAnswerAsPartsPlacedFlat) {
    std::vector<ChainSphere> spheres;
    std::vector<ChainCylinder> cylinders;
    for (int k = 0; k < 8; ++k) {
        spheres.push_back({{0.3 * std::sin(k), 0.3 * std::cos(k), 0.4 * k}, 0.05});
        if (k) cylinders.push_back({k - 1, k, 0.05});
    }
    const ChainShape chain(spheres, cylinders);
    const Vec3 far{1e6 + 0.3, -2e6 + 0.7, 3e5 + 0.1};
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-2, 2), angle(0, 6.28);
    std::vector<Transform> xf;
    for (int i = 0; i < 40; ++i)
        xf.push_back(Transform::translate(far + Vec3{u(rng), u(rng), u(rng)}) *
                     Transform::rotate({1, 0.3, 0.2}, angle(rng)));
    std::vector<AccelObject> objects;
    for (const Transform& x : xf) objects.push_back({&chain, &x});
    const EmbreeAccel flat(objects, {.instancing = Instancing::kNever});
    const EmbreeAccel instanced(objects, {.instancing = Instancing::kAlways});

    // A camera 30 units off, rays over a 6 x 6 window through the crowd: many graze a hair.
    const Vec3 eye = far + Vec3{0, -30, 2};
    int hits = 0, differ = 0;
    for (int j = 0; j < 300; ++j)
        for (int i = 0; i < 300; ++i) {
            const Vec3 at = far + Vec3{-3 + i / 50.0, 0, -3 + j / 50.0};
            const Ray r{eye, normalize(at - eye)};
            AccelHit a, b;
            const bool ha = flat.intersect(r, 0, kInfinity, a);
            const bool hb = instanced.intersect(r, 0, kInfinity, b);
            hits += ha;
            differ += ha != hb || (ha && (a.object != b.object || a.t != b.t));
        }
    EXPECT_GT(hits, 2000);  // the window holds the crowd
    EXPECT_EQ(differ, 0);
}

// A shape culled by two thin capsules (a lattice's cull parts): a diagonal one across the unit
// cube and one far from it. It meets nothing; it counts the rays the accelerator hands its
// own cull test (CullParts::cull_meets), those its capsules in world space did not turn away.
class TwoCapsules final : public Shape, public CullParts {
public:
    Bounds3 bounds() const override { return {{-0.05, -0.05, -0.05}, {6.05, 6.05, 6.05}}; }
    bool intersect(const Ray&, double, double, Crossing&) const override { return false; }
    void spans(const Ray&, SpanList&) const override {}
    Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
    bool inside(Vec3) const override { return false; }

    std::size_t cull_count() const override { return 2; }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double) const override {
        return expand(xf.bounds(Bounds3{capsule(i).a, capsule(i).b}), kRadius);
    }
    bool cull_meets(std::size_t i, const Ray& r) const override {
        ++tests;
        return capsule(i).meets_line(r.o, r.d, kRadius);
    }
    bool cull_capsule(std::size_t i, const Transform& xf, double, Capsule& c) const override {
        c = {xf.point(capsule(i).a), xf.point(capsule(i).b), kRadius};
        return true;
    }

    mutable int tests = 0;

private:
    static Capsule capsule(std::size_t i) {
        return i == 0 ? Capsule{{0, 0, 0}, {1, 1, 1}, kRadius} : Capsule{{5, 5, 5}, {6, 6, 6}, kRadius};
    }
};

// Rays through the diagonal capsule's box, half a unit from it: its capsule in world space
// turns them all away, far from the origin as at it (in world-space float, 1e7 out, its ends
// were rounded to whole units, and it was grown by as much to hold the exact one).
TEST(AccelFrame, FarFromTheOriginCullCapsulesTurnAwayWhatTheyMiss) {
    for (const Vec3 corner : {Vec3{0, 0, 0}, Vec3{1e7 + 0.37, -1e7 + 0.41, 1e7 + 0.29}}) {
        const TwoCapsules shape;
        std::vector<Transform> xf;
        for (int i = 0; i < 10; ++i) xf.push_back(Transform::translate(corner + Vec3{10.0 * i, 0, 0}));
        std::vector<AccelObject> objects;
        for (const Transform& x : xf) objects.push_back({&shape, &x});
        const EmbreeAccel accel(objects);
        for (int i = 0; i < 10; ++i) {
            const Ray r{corner + Vec3{10.0 * i + 0.9, 0.1, -5}, {0, 0, 1}};
            AccelHit hit;
            EXPECT_FALSE(accel.intersect(r, 0, kInfinity, hit));
        }
        EXPECT_EQ(shape.tests, 0) << "shapes at " << corner.x;
    }
}

}  // namespace
}  // namespace lat
