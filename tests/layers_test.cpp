// Tracing through partial hits (coverage/layers.h): EmbreeAccel::intersect_layers finds
// the partial crossings in ray order, each object's once, stops where compositing stops without
// changing what it composites, and sums shadow rays' transmittance; and the shading of a mean
// of normals (phong_term's normal_length) keeps the light the specular lobe reflects and takes
// the mean of the clamped diffuse terms.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>

#include "accel/embree_accel.h"
#include "coverage/layer_composite.h"
#include "coverage/layers.h"
#include "coverage/sheets.h"
#include "geometry/parts.h"
#include "render/core/shading.h"

namespace lat {
namespace {

// A unit square at height z, met by a ray with coverage alpha, as a prefiltered lattice's sheet
// is; culled by `parts` boxes, so that a traversal meets each object several times.
class Sheet final : public Shape, public CullParts {
public:
    Sheet(double z, float alpha, std::size_t parts, double tolerance = 0)
        : z_(z), alpha_(alpha), parts_(parts), tolerance_(tolerance) {}
    Bounds3 bounds() const override { return {{-1, -1, z_ - 0.01}, {1, 1, z_ + 0.01}}; }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override {
        if (r.d.z == 0) return false;
        const double t = (z_ - r.o.z) / r.d.z;
        const Vec3 p = r.at(t);
        if (!(t > tmin && t < tmax) || std::abs(p.x) > 1 || std::abs(p.y) > 1) return false;
        hit = Crossing(t, 0, SurfacePoint{p, {0, 0, 1}});
        hit.coverage = alpha_;
        return true;
    }
    void spans(const Ray&, SpanList&) const override {}
    Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
    bool inside(Vec3) const override { return false; }
    double surface_tolerance() const override { return tolerance_; }
    bool cull_meets(std::size_t, const Ray&) const override { return true; }
    std::size_t cull_count() const override { return parts_; }
    // Boxes reaching farther and farther back along the ray, so that a traversal meets other
    // objects between the parts of one (more than the ring of tested objects holds).
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double) const override {
        return xf.bounds(Bounds3{{-1, -1, z_ - 6.0 * double(i) - 0.01}, {1, 1, z_ + 0.01}});
    }

private:
    double z_;
    float alpha_;
    std::size_t parts_;
    double tolerance_;
};

struct Stack {
    std::vector<std::unique_ptr<Sheet>> sheets;
    std::vector<float> alpha;  // by height, z = 1, 2, ...
    std::vector<int> height;   // by object
    Transform xf;
    std::unique_ptr<EmbreeAccel> accel;

    // n sheets, made in a shuffled order so that object order is not ray order; the one at
    // height `opaque` (if any) covers fully.
    explicit Stack(int n, int opaque = -1, double tolerance = 0) {
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.2f, 0.6f);
        std::vector<int> order(static_cast<std::size_t>(n));
        std::iota(order.begin(), order.end(), 1);
        std::shuffle(order.begin(), order.end(), rng);
        alpha.assign(static_cast<std::size_t>(n) + 1, 0);
        std::vector<AccelObject> objects;
        for (const int z : order) {
            const float a = z == opaque ? 1.0f : u(rng);
            alpha[static_cast<std::size_t>(z)] = a;
            height.push_back(z);
            sheets.push_back(std::make_unique<Sheet>(z, a, 3, tolerance));
            objects.push_back({sheets.back().get(), &xf});
        }
        accel = std::make_unique<EmbreeAccel>(objects);
    }
};

const Ray kUp{{0.1, 0.2, 0}, {0, 0, 1}};

TEST(Layers, PartialCrossingsInRayOrderEachObjectOnce) {
    const Stack s(20);
    AccelHit hit;
    std::vector<AccelHit> partial;
    EXPECT_FALSE(s.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, partial));
    ASSERT_EQ(partial.size(), 20u);
    for (std::size_t i = 0; i < partial.size(); ++i) {
        EXPECT_NEAR(partial[i].t, double(i + 1), 1e-12);
        EXPECT_EQ(partial[i].crossing.coverage, s.alpha[i + 1]);
    }
}

TEST(Layers, StoppingWhereCompositingStopsKeepsTheLayersItUses) {
    const Stack s(20);
    AccelHit hit;
    std::vector<AccelHit> all, cut;
    s.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, all);
    // At most 8 layers: exactly the first 8.
    s.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, cut, {.max_layers = 8});
    ASSERT_EQ(cut.size(), 8u);
    for (std::size_t i = 0; i < cut.size(); ++i) EXPECT_EQ(cut[i].t, all[i].t);
    // Down to 5 % left: up to the first layer that gets there, and no farther.
    const double min_left = 0.05;
    s.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, cut,
                              {.max_layers = 100, .min_left = min_left});
    double left = 1;
    std::size_t used = 0;
    while (left > min_left) left *= 1 - double(all[used++].crossing.coverage);
    ASSERT_EQ(cut.size(), used);
    for (std::size_t i = 0; i < cut.size(); ++i) EXPECT_EQ(cut[i].t, all[i].t);
}

TEST(Layers, ShadowRaysSumTransmittanceAndStopWhenBlocked) {
    const Stack clear(6), blocked(6, 4);
    AccelHit hit;
    std::vector<AccelHit> partial;
    EXPECT_FALSE(clear.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, partial,
                                               {.blocked_below = 1e-6}));
    double expected = 1, got = 1;
    for (int z = 1; z <= 6; ++z) expected *= 1 - double(clear.alpha[static_cast<std::size_t>(z)]);
    for (const AccelHit& h : partial) got *= 1 - double(h.crossing.coverage);
    EXPECT_NEAR(got, expected, 1e-12);
    EXPECT_TRUE(blocked.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, partial,
                                                {.blocked_below = 1e-6}));
    // Let through less than asked: blocked.
    EXPECT_TRUE(clear.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, partial,
                                              {.blocked_below = expected * 1.01}));
}

// A shadow ray worth little to its pixel (a layer deep behind partial sheets, a faint light)
// is traced only until what it could still add is under kMinShadowContribution: it stops at
// the first sheet that takes it there, sooner the less it is worth, so what blocking it drops
// is always under that; worth 1 keeps a front layer's precision.
TEST(Layers, AShadowRayIsTracedOnlyAsFarAsItsPixelCanTell) {
    EXPECT_EQ(shadow_stop(1).blocked_below, kMinTransmittance);
    EXPECT_EQ(shadow_stop(1e-9).blocked_below, 1.0);
    const Stack s(12);
    AccelHit hit;
    std::vector<AccelHit> all;
    s.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, all);
    std::size_t read_before = all.size() + 1;
    for (const double worth : {1.0, 0.1, 0.01, 1e-3}) {
        std::vector<AccelHit> cut;
        const bool blocked = s.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject,
                                                       hit, cut, shadow_stop(worth));
        // What got through, sheet by sheet: the ray reads up to the first sheet that takes it
        // under the stop, and no farther.
        double left = 1;
        std::size_t used = 0;
        while (used < all.size() && left >= shadow_stop(worth).blocked_below)
            left *= 1 - double(all[used++].crossing.coverage);
        ASSERT_EQ(blocked, left < shadow_stop(worth).blocked_below) << "worth " << worth;
        if (blocked) {
            EXPECT_LT(left * worth, kMinShadowContribution) << "worth " << worth;
        }
        EXPECT_LE(cut.size(), used) << "worth " << worth;
        EXPECT_LT(used, read_before) << "worth " << worth;
        read_before = used;
    }
}

// Shadow rays in a run that keeps what blocked the last of them (EmbreeAccel::LastBlocker):
// the same answer and the same partial crossings as each alone, whether the kept sheet blocks
// the next ray, lets it through partly, or lies out of its reach.
TEST(Layers, ARunOfShadowRaysKeepingItsBlockerAnswersAsEachAlone) {
    const Stack clear(6), blocked(6, 4);
    const auto crossings = [](const std::vector<AccelHit>& hits) {
        std::vector<std::pair<double, std::uint32_t>> out;
        for (const AccelHit& h : hits) out.emplace_back(h.t, h.object);
        return out;
    };
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> xy(-1.3, 1.3), z0(0, 6.5);
    std::uniform_int_distribution<std::uint32_t> self(0, 7);  // past 5: none
    for (const Stack* s : {&clear, &blocked})
        for (const double below : {0.05, 0.3}) {
            EmbreeAccel::LastBlocker last;
            int stopped = 0;
            for (int i = 0; i < 400; ++i) {
                const Ray r{{xy(rng), xy(rng), z0(rng)}, {0, 0, 1}};
                const std::uint32_t from = self(rng);
                AccelHit hit_alone, hit_run;
                std::vector<AccelHit> alone, run;
                const bool a = s->accel->intersect_layers(r, 0, kInfinity, from, hit_alone, alone,
                                                          {.blocked_below = below});
                const bool b = s->accel->intersect_layers(r, 0, kInfinity, from, hit_run, run,
                                                          {.blocked_below = below}, &last);
                ASSERT_EQ(a, b) << i;
                stopped += a;
                if (!a) {
                    EXPECT_EQ(crossings(alone), crossings(run)) << i;
                }
            }
            EXPECT_GT(stopped, 20);
            EXPECT_LT(stopped, 380);
        }
}

// A shadow ray tests the object it leaves (`self`) after the traversal, if nothing else
// blocked it: the crossings it finds are the same whichever object it leaves (these sheets
// have no surface tolerance, and lie ahead of the ray's start), and an opaque sheet blocks a
// ray leaving it, in a transmittance and in plain occlusion alike.
TEST(Layers, AShadowRayTestsTheObjectItLeavesAfterTheOthers) {
    const Stack clear(6), blocked(6, 4);
    const LayerStop shadow{.blocked_below = 1e-6};
    AccelHit hit;
    std::vector<AccelHit> none, mine;
    ASSERT_FALSE(clear.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit,
                                               none, shadow));
    ASSERT_EQ(none.size(), 6u);
    for (std::uint32_t self = 0; self < 6; ++self) {
        EXPECT_FALSE(clear.accel->intersect_layers(kUp, 0, kInfinity, self, hit, mine, shadow));
        ASSERT_EQ(mine.size(), none.size()) << self;
        for (std::size_t i = 0; i < mine.size(); ++i) {
            EXPECT_EQ(mine[i].object, none[i].object) << self;
            EXPECT_EQ(mine[i].t, none[i].t) << self;
        }
    }
    // The opaque sheet: the closest opaque crossing of a camera ray.
    ASSERT_TRUE(blocked.accel->intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, none));
    const std::uint32_t opaque = hit.object;
    EXPECT_TRUE(blocked.accel->intersect_layers(kUp, 0, kInfinity, opaque, hit, mine, shadow));
    EXPECT_EQ(hit.object, opaque);  // the others let enough through: it blocks
    EXPECT_TRUE(blocked.accel->occluded(kUp, 3.5, 4.5, opaque));  // only it lies in range
}

// A ray leaving an object skips that object's crossings within its surface tolerance, and no
// other's: the object is the one the caller numbers `self` (the accelerator numbers objects in
// its own order, here not the order given).
TEST(Layers, ARayLeavingAnObjectSkipsItsOwnCrossingsWithinItsTolerance) {
    const Stack s(8, -1, 1e-3);
    const LayerStop shadow{.blocked_below = 1e-6};
    AccelHit hit;
    std::vector<AccelHit> partial;
    for (std::uint32_t self = 0; self < 8; ++self) {
        const double z = s.height[self];
        const Ray up{{0.1, 0.2, z - 1e-4}, {0, 0, 1}};  // just below its own sheet
        s.accel->intersect_layers(up, 0, kInfinity, self, hit, partial, shadow);
        ASSERT_EQ(partial.size(), 8 - static_cast<std::size_t>(z)) << self;  // those above only
        for (const AccelHit& h : partial) EXPECT_NE(h.object, self);
        s.accel->intersect_layers(up, 0, kInfinity, self, hit, partial);  // a camera ray's too
        EXPECT_EQ(partial.size(), 8 - static_cast<std::size_t>(z)) << self;
        // Plain occlusion: nothing within its own tolerance, the one just beyond it the other's.
        const std::uint32_t other = (self + 1) % 8;
        const Ray below_other{{0.1, 0.2, s.height[other] - 1e-4}, {0, 0, 1}};
        EXPECT_FALSE(s.accel->occluded(up, 0, 5e-4, self)) << self;
        EXPECT_TRUE(s.accel->occluded(below_other, 0, 5e-4, self)) << self;
    }
}

// The specular light phong_term reflects over the sphere of view directions, for a normal of
// this length (light along the normal, so that the lobe is centred on it).
double specular_integral(double normal_length) {
    Material m;
    m.kd = 0, m.ks = 0.5, m.shininess = 30;
    const Vec3 n{0, 0, 1};
    const int steps = 20000;
    double sum = 0;
    for (int i = 0; i < steps; ++i) {
        const double theta = (i + 0.5) * (M_PI / 2) / steps;
        const Vec3 v{std::sin(theta), 0, std::cos(theta)};
        sum += phong_term(m, {1, 1, 1}, n, n, v, {1, 1, 1}, normal_length).x * 2 * M_PI *
               std::sin(theta) * (M_PI / 2) / steps;
    }
    return sum;
}

// A lattice whose sub-rays meet it at two depths (SheetSource): half of them on a unit square
// at height z, the other half at z + dz, each sheet with its sub-rays' normals (k sheet's
// k-th: turned k + 1 about x); culled by several boxes, as Sheet.
class TwoSheets final : public Shape, public SheetSource, public CullParts {
public:
    // reach: how far back along the ray each cull box reaches beyond the one before.
    TwoSheets(double z, double dz, double reach = 6) : z_(z), dz_(dz), reach_(reach) {}
    Bounds3 bounds() const override { return {{-1, -1, z_ - 0.01}, {1, 1, z_ + dz_ + 0.01}}; }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override {
        std::array<SheetCrossing, kMaxSheets> c;
        if (sheets(r, tmin, tmax, c) == 0) return false;
        hit = c[0].crossing;
        return true;
    }
    int sheets(const Ray& r, double tmin, double tmax,
               std::span<SheetCrossing, kMaxSheets> out) const override {
        int n = 0;
        for (const auto& [z, sub_rays] : {std::pair{z_, 0b0011}, std::pair{z_ + dz_, 0b1100}}) {
            const double t = (z - r.o.z) / r.d.z;
            if (!(t > tmin && t < tmax)) continue;
            SheetCrossing& s = out[static_cast<std::size_t>(n++)];
            s.crossing = Crossing(t, 0, SurfacePoint{r.at(t), {0, 0, 1}});
            s.crossing.coverage = 0.5f;
            s.crossing.sub_rays = static_cast<std::uint8_t>(sub_rays);
            s.normals.count = 2;
            for (std::size_t k = 0; k < 2; ++k) s.normals.n[k] = normal_of(k, sub_rays);
        }
        return n;
    }
    static Vec3 normal_of(std::size_t k, int sub_rays) {
        const double a = 0.1 * double(k + 1) * (sub_rays == 0b0011 ? 1 : -1);
        return {0, std::sin(a), std::cos(a)};
    }
    void spans(const Ray&, SpanList&) const override {}
    Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
    bool inside(Vec3) const override { return false; }
    bool cull_meets(std::size_t, const Ray&) const override { return true; }
    std::size_t cull_count() const override { return 3; }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double) const override {
        return xf.bounds(
            Bounds3{{-1, -1, z_ - reach_ * double(i) - 0.01}, {1, 1, z_ + dz_ + 0.01}});
    }

private:
    double z_, dz_, reach_;
};

// Met by a ray and never crossed, culled by two boxes: it fills the ring of tested objects.
class Nothing final : public Shape, public CullParts {
public:
    explicit Nothing(double z) : z_(z) {}
    Bounds3 bounds() const override { return {{-1, -1, z_ - 0.01}, {1, 1, z_ + 0.01}}; }
    bool intersect(const Ray&, double, double, Crossing&) const override { return false; }
    void spans(const Ray&, SpanList&) const override {}
    Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
    bool inside(Vec3) const override { return false; }
    bool cull_meets(std::size_t, const Ray&) const override { return true; }
    std::size_t cull_count() const override { return 2; }
    Bounds3 cull_bounds(std::size_t, const Transform& xf, double) const override {
        return xf.bounds(bounds());
    }

private:
    double z_;
};

// A camera ray keeps every sheet of an object, in ray order among the other objects' crossings,
// once however many of its cull boxes the traversal meets (also when more objects than the
// ring of tested ones holds lie between them); a sheet beyond an opaque crossing is cut.
TEST(Layers, AnObjectsSheetsAreEachKeptOnce) {
    const TwoSheets two(1, 2);
    const Sheet between(2, 0.3f, 3), opaque(2.5, 1.0f, 3);
    const Transform xf;
    const std::vector<AccelObject> objects{{&two, &xf}, {&between, &xf}};
    const EmbreeAccel accel(objects);
    AccelHit hit;
    std::vector<AccelHit> partial;
    EXPECT_FALSE(accel.intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, partial));
    ASSERT_EQ(partial.size(), 3u);
    const double t[] = {1, 2, 3};
    const std::uint32_t object[] = {0, 1, 0};
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR(partial[i].t, t[i], 1e-12);
        EXPECT_EQ(partial[i].object, object[i]);
    }
    EXPECT_EQ(partial[0].crossing.sub_rays, 0b0011);
    EXPECT_EQ(partial[2].crossing.sub_rays, 0b1100);
    for (const std::size_t i : {0u, 2u}) {  // each with its sub-rays' normals
        ASSERT_EQ(partial[i].normals.count, 2);
        for (std::size_t k = 0; k < 2; ++k)
            EXPECT_EQ(partial[i].normals.n[k],
                      TwoSheets::normal_of(k, partial[i].crossing.sub_rays));
    }
    EXPECT_EQ(partial[1].normals.count, 0);

    // Its cull boxes 20 apart along the ray, 12 objects between them: visited again.
    const TwoSheets far(1, 2, 20);
    std::vector<std::unique_ptr<Nothing>> between_boxes;
    std::vector<AccelObject> crowd{{&far, &xf}};
    for (int i = 0; i < 12; ++i) {
        between_boxes.push_back(std::make_unique<Nothing>(-35.0 + i));
        crowd.push_back({between_boxes.back().get(), &xf});
    }
    const EmbreeAccel crowd_accel(crowd);
    const Ray from_below{{0.1, 0.2, -50}, {0, 0, 1}};
    EXPECT_FALSE(crowd_accel.intersect_layers(from_below, 0, kInfinity, EmbreeAccel::kNoObject, hit,
                                              partial));
    ASSERT_EQ(partial.size(), 2u);
    EXPECT_EQ(partial[0].crossing.sub_rays, 0b0011);
    EXPECT_EQ(partial[1].crossing.sub_rays, 0b1100);

    const std::vector<AccelObject> cut{{&two, &xf}, {&opaque, &xf}};
    const EmbreeAccel cut_accel(cut);
    EXPECT_TRUE(
        cut_accel.intersect_layers(kUp, 0, kInfinity, EmbreeAccel::kNoObject, hit, partial));
    EXPECT_NEAR(hit.t, 2.5, 1e-12);
    ASSERT_EQ(partial.size(), 1u);
    EXPECT_NEAR(partial[0].t, 1, 1e-12);
}

// Partial crossings compose: without sub-rays as independent draws (what is left is the
// product of 1 - coverage, in any order); with sub-rays as the sub-rays themselves (a sub-ray
// blocked once is not blocked again, and a ray whose sub-rays are all blocked is covered).
TEST(Layers, CrossingsWithSubRaysBlockEachSubRayOnce) {
    LayerComposite c;
    EXPECT_EQ(c.left(), 1.0);
    EXPECT_DOUBLE_EQ(c.add(0.5, 0b0011), 0.5);
    EXPECT_DOUBLE_EQ(c.add(0.5, 0b0011), 0.0);  // the same sub-rays: nothing new
    EXPECT_DOUBLE_EQ(c.add(0.5, 0b0110), 0.5);  // one of the two left
    EXPECT_DOUBLE_EQ(c.left(), 0.25);
    EXPECT_DOUBLE_EQ(c.add(0.5, 0), 0.5);  // no sub-rays: half of what is left
    EXPECT_DOUBLE_EQ(c.left(), 0.125);
    EXPECT_DOUBLE_EQ(c.add(0.25, 0b1000), 1.0);
    EXPECT_EQ(c.left(), 0.0);
    EXPECT_EQ(c.add(0.5, 0), 1.0);  // nothing left to cover
    EXPECT_EQ(c.draws(), 2);        // crossings without sub-rays: what a layer limit counts

    // Any order, the same left.
    const std::vector<std::pair<double, std::uint8_t>> layers{
        {0.3, 0}, {0.5, 0b0101}, {0.25, 0b0001}, {0.6, 0}, {0.5, 0b1100}};
    std::vector<int> order(layers.size());
    std::iota(order.begin(), order.end(), 0);
    double first = -1;
    do {
        LayerComposite d;
        for (const int i : order) d.add(layers[i].first, layers[i].second);
        if (first < 0) first = d.left();
        EXPECT_NEAR(d.left(), first, 1e-15);
    } while (std::next_permutation(order.begin(), order.end()));
    EXPECT_NEAR(first, 0.7 * 0.4 * 0.25, 1e-15);
}

// A shape that records the footprint the accelerator handed it with the ray.
class Probe final : public Shape {
public:
    Bounds3 bounds() const override { return {{-1, -1, -1}, {1, 1, 1}}; }
    bool intersect(const Ray& r, double, double, Crossing&) const override {
        handed = r.footprint != nullptr;
        seen = handed ? *r.footprint : RayFootprint{};
        local_d = r.d;
        return false;
    }
    void spans(const Ray&, SpanList&) const override {}
    Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
    bool inside(Vec3) const override { return false; }
    mutable bool handed = false;
    mutable RayFootprint seen;
    mutable Vec3 local_d;
};

// The accelerator hands an object the ray's footprint in its own space: its width, spread and
// purpose, its own bound (AccelObject::widest_footprint), and the world's directions across the
// ray where its map is a similarity (turned and evenly scaled: still across the ray, as long as
// its direction), none where it is not (sheared or unevenly scaled). A ray without a footprint
// hands none.
TEST(Layers, ObjectsGetTheRaysFootprintInTheirSpace) {
    const Probe probe;
    const Vec3 o{0.3, -0.2, -5}, d = normalize(Vec3{0.1, 0.2, 1});
    const RayFootprint world = footprint_across(d, 0.25, 0.01, true);
    const auto handed = [&](const Transform& xf, const Ray& r) {
        const std::vector<AccelObject> objects{{&probe, &xf, 0.75}};
        const EmbreeAccel accel(objects);
        AccelHit hit;
        probe.handed = false;
        probe.seen = {};
        accel.intersect(r, 0.0, kInfinity, hit);
        return probe.seen;
    };
    const Transform similar = Transform::rotate({1, 2, 3}, 0.7) * Transform::scale({3, 3, 3});
    const Transform uneven = Transform::scale({1, 1.01, 1});
    const RayFootprint a = handed(similar, {o, d, &world});
    ASSERT_TRUE(probe.handed);
    ASSERT_TRUE(a.across);
    EXPECT_NEAR(length(similar.vector(a.u) - world.u), 0.0, 1e-12);
    EXPECT_NEAR(length(similar.vector(a.v) - world.v), 0.0, 1e-12);
    EXPECT_NEAR(dot(a.u, probe.local_d), 0.0, 1e-12);
    EXPECT_NEAR(length(a.u), length(probe.local_d), 1e-12);
    EXPECT_EQ(a.width0, 0.25);
    EXPECT_EQ(a.spread, 0.01);
    EXPECT_TRUE(a.coverage_only);
    EXPECT_EQ(a.widest, 0.75);
    EXPECT_FALSE(handed(uneven, {o, d, &world}).across);
    EXPECT_TRUE(probe.handed);
    EXPECT_EQ(probe.seen.widest, 0.75);
    EXPECT_TRUE(handed(Transform{}, {o, d, &world}).across);
    EXPECT_EQ(probe.seen.u, world.u);
    handed(similar, {o, d});
    EXPECT_FALSE(probe.handed);
}

TEST(Layers, AMeanNormalWidensTheSpecularLobeKeepingItsLight) {
    const double unit = specular_integral(1.0);
    EXPECT_NEAR(unit, 2 * M_PI * 0.5 / 31, 1e-4);
    for (const double len : {0.999, 0.99, 0.9})
        EXPECT_NEAR(specular_integral(len) / unit, 1.0, 1e-3) << len;
    // Wider: the peak is lower.
    Material m;
    m.kd = 0;
    const Vec3 n{0, 0, 1};
    EXPECT_LT(phong_term(m, {1, 1, 1}, n, n, n, {1, 1, 1}, 0.99).x,
              phong_term(m, {1, 1, 1}, n, n, n, {1, 1, 1}, 1.0).x);
}

// The diffuse term of a mean normal is the mean of clamped terms (diffuse_mean): for a normal
// n.l of the stated mean and variance, by numerical integration; at length 1 the plain term.
TEST(Layers, TheDiffuseTermOfAMeanNormalIsTheMeanOfClampedTerms) {
    for (const double len : {0.0, 0.3, 0.7, 0.95})
        for (const double nl : {-0.9, -0.3, 0.0, 0.4, 1.0}) {
            const double mean = len * nl, sd = std::sqrt((1 - len * len) / 3);
            double sum = 0, w = 0;
            for (int i = -4000; i <= 4000; ++i) {
                const double z = i / 500.0, g = std::exp(-0.5 * z * z);
                sum += g * std::max(0.0, mean + sd * z), w += g;
            }
            EXPECT_NEAR(diffuse_mean(nl, len), sum / w, 1e-6) << len << " " << nl;
            EXPECT_GE(diffuse_mean(nl, len), std::max(0.0, mean));
        }
    EXPECT_EQ(diffuse_mean(0.4, 1.0), 0.4);
    EXPECT_EQ(diffuse_mean(-0.4, 1.0), 0.0);
    // Unit normals spread evenly over the half of a cylinder that faces the viewer, lit from
    // the side: their mean clamped term is closer to diffuse_mean of their mean normal than to
    // the clamped term of that mean.
    const Vec3 l = normalize(Vec3{1, 0, 0.3});
    Vec3 mean_n;
    double truth = 0;
    const int k = 2000;
    for (int i = 0; i < k; ++i) {
        const double a = M_PI * ((i + 0.5) / k - 0.5);
        const Vec3 ni{std::sin(a), -std::cos(a), 0};
        mean_n += ni / k, truth += std::max(0.0, dot(ni, l)) / k;
    }
    const double len = length(mean_n), nl = dot(mean_n / len, l);
    EXPECT_LT(std::abs(diffuse_mean(nl, len) - truth), std::abs(len * std::max(0.0, nl) - truth));
}

}  // namespace
}  // namespace lat
