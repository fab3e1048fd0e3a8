// lattice/part_boxes.h: the float box test never rejects a part whose exact box the ray meets
// in the range asked (what keeps candidates images identical to exact mode), from near and
// from far, along axes and grazing box corners.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "geometry/chain.h"
#include "lattice/part_boxes.h"

namespace lat {
namespace {

// A shape of parts that are boxes only (part_count, part_bounds): PartBoxes asks for nothing
// else.
class BoxParts : public Shape, public Parts {
public:
    using Parts::part_bounds;
    bool intersect(const Ray&, double, double, Crossing&) const override { return false; }
    void spans(const Ray&, SpanList&) const override {}
    Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
    bool inside(Vec3) const override { return false; }
    Bounds3 part_bounds(std::size_t i, const Transform& xf) const override {
        return xf.bounds(part_bounds(i));
    }
    bool intersect_part(std::size_t, const Ray&, double, double, Crossing&) const override {
        return false;
    }
    bool occluded_part(std::size_t, const Ray&, double, double) const override { return false; }
    void part_spans(std::size_t, const Ray&, SpanList&) const override {}
    void part_spheres(std::size_t, std::vector<BoundingSphere>&) const override {}
};

class Boxes final : public BoxParts {
public:
    using BoxParts::part_bounds;
    std::vector<Bounds3> parts;
    Bounds3 bounds() const override { return {{0, 0, 0}, {7, 7, 20}}; }
    std::size_t part_count() const override { return parts.size(); }
    Bounds3 part_bounds(std::size_t i) const override { return parts[i]; }
};

// The exact answer, in long double, on the unpadded box.
bool meets_exact(const Bounds3& b, const Ray& r, double tmin, double tmax) {
    long double lo = tmin, hi = tmax;
    for (std::size_t k = 0; k < 3; ++k) {
        const long double o = r.o[k], d = r.d[k];
        if (d == 0) {
            if (o < b.lo[k] || o > b.hi[k]) return false;
            continue;
        }
        const long double t0 = (b.lo[k] - o) / d, t1 = (b.hi[k] - o) / d;
        lo = std::max(lo, std::min(t0, t1));
        hi = std::min(hi, std::max(t0, t1));
    }
    return lo <= hi;
}

// n random boxes in the primitive's box, half-sizes up to (h, h, hz).
Boxes random_boxes(std::mt19937& rng, int n, double h, double hz) {
    std::uniform_real_distribution<double> u(0, 1);
    Boxes prim;
    for (int i = 0; i < n; ++i) {
        const Vec3 c{7 * u(rng), 7 * u(rng), 20 * u(rng)};
        const Vec3 half{h * u(rng), h * u(rng), hz * u(rng)};
        prim.parts.push_back(lat::intersect(Bounds3{c - half, c + half}, prim.bounds()));
    }
    return prim;
}

TEST(PartBoxes, FloatTestNeverRejectsAPartTheRayMeets) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    const Boxes prim = random_boxes(rng, 200, 0.3, 1.5);
    const PartBoxes boxes(ShapeParts(prim), prim.bounds());
    int met = 0;
    for (int n = 0; n < 20000; ++n) {
        const Bounds3& target = prim.parts[static_cast<std::size_t>(n) % prim.parts.size()];
        // Aim at a corner of a part (grazing) or inside it, from 1 to 1e5 units away.
        Vec3 p = target.lo + (target.hi - target.lo) * Vec3{u(rng), u(rng), u(rng)};
        if (n % 3 == 0) p = target.hi;
        Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        if (n % 7 == 0) d = {0, 0, 1};  // along an axis: the double fallback
        const double dist = std::pow(10.0, 5 * u(rng));
        const double scale = 0.01 + 10 * u(rng);  // instance scaling lengthens or shortens d
        const Ray r{p - d * dist, d * scale};
        const double t_hit = dist / scale;
        const double tmin = n % 2 ? 0.0 : t_hit * u(rng),
                     tmax = n % 5 ? kInfinity : t_hit * (1 + u(rng));
        const PartBoxes::Ray4 q(boxes, r);
        const PartBoxes::Ray4::Range range = q.range(tmin, tmax);
        for (std::uint32_t i = 0; i < prim.parts.size(); ++i)
            if (meets_exact(prim.parts[i], r, tmin, tmax)) {
                ++met;
                ASSERT_TRUE(q.meets(i, range)) << "ray " << n << " part " << i;
            }
    }
    EXPECT_GT(met, 20000);
}

// meets_listed answers for each listed part (one to four, in any order, repeats allowed) what
// meets answers for it alone, in float and in the double fallback.
TEST(PartBoxes, ListedPartsFourAtATimeAnswerAsOneAtATime) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0, 1);
    const Boxes prim = random_boxes(rng, 40, 0.3, 1.5);
    const PartBoxes boxes(ShapeParts(prim), prim.bounds());
    std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(prim.parts.size() - 1));
    int met = 0, missed = 0;
    for (int n = 0; n < 5000; ++n) {
        const std::uint32_t aimed = pick(rng);  // listed too, in some lane
        const Bounds3& target = prim.parts[aimed];
        const Vec3 p = target.lo + (target.hi - target.lo) * Vec3{u(rng), u(rng), u(rng)};
        Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        if (n % 7 == 0) d = {0, 0, 1};  // along an axis: the double fallback
        const Ray r{p - d * 20.0, d};
        const PartBoxes::Ray4 q(boxes, r);
        const PartBoxes::Ray4::Range range = q.range(n % 2 ? 0.0 : 20 * u(rng), n % 3 ? kInfinity : 25.0);
        std::uint32_t parts[4];
        const std::size_t count = 1 + static_cast<std::size_t>(n % 4);
        for (std::size_t j = 0; j < count; ++j) parts[j] = pick(rng);
        parts[static_cast<std::size_t>(n / 4) % count] = aimed;
        const unsigned mask = q.meets_listed(parts, count, range);
        EXPECT_EQ(mask >> count, 0u) << "ray " << n;
        for (std::size_t j = 0; j < count; ++j) {
            const bool alone = q.meets(parts[j], range);
            ASSERT_EQ((mask >> j & 1u) != 0, alone) << "ray " << n << " lane " << j;
            (alone ? met : missed) += 1;
        }
    }
    EXPECT_GT(met, 1000);
    EXPECT_GT(missed, 1000);
}

// near_parts keeps every part that a ray parallel to r, shifted by up to g along each axis (the
// box grown by g), meets after tmin: the sub-rays of a filtered lattice's exact blend.
TEST(PartBoxes, NearPartsKeepEveryPartAParallelRayWithinGrowMeets) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    const Boxes prim = random_boxes(rng, 60, 0.2, 1.0);
    const PartBoxes boxes(ShapeParts(prim), prim.bounds(), true);  // 60 parts: through the tree
    std::vector<std::uint32_t> near(prim.parts.size());
    int kept = 0, met = 0;
    for (int n = 0; n < 20000; ++n) {
        const Bounds3& target = prim.parts[static_cast<std::size_t>(n) % prim.parts.size()];
        const Vec3 p = target.lo + (target.hi - target.lo) * Vec3{u(rng), u(rng), u(rng)};
        Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        if (n % 7 == 0) d = {0, 1, 0};  // along an axis: the double fallback
        const double dist = std::pow(10.0, 4 * u(rng));
        const double g = std::pow(10.0, 3 * u(rng) - 2.5);  // 0.003 to 3 cells
        const Ray r{p - d * dist, d * (0.1 + 5 * u(rng))};
        const double tmin = n % 2 ? 0.0 : dist / length(r.d) * u(rng);
        const std::size_t count = boxes.near_parts(r, g, tmin, near);
        kept += static_cast<int>(count);
        for (int k = 0; k < 8; ++k) {
            // A shift of up to g along each axis (a cube corner when k = 0).
            const Vec3 s = k == 0 ? Vec3{g, -g, g}
                                  : Vec3{u(rng) * 2 - 1, u(rng) * 2 - 1, u(rng) * 2 - 1} * g;
            const Ray shifted{r.o + s, r.d};
            for (std::uint32_t i = 0; i < prim.parts.size(); ++i) {
                if (!meets_exact(prim.parts[i], shifted, tmin, kInfinity)) continue;
                ++met;
                ASSERT_TRUE(std::find(near.begin(), near.begin() + count, i) != near.begin() + count)
                    << "ray " << n << " part " << i;
            }
        }
    }
    EXPECT_GT(met, 20000);
    EXPECT_LT(kept, 20000 * 20);  // and it does leave parts out
}

// near_parts tests four boxes at a time: the parts it keeps, in order, are those the one-box
// test keeps, for every count of parts modulo 4 (lanes past the last part never reported).
TEST(PartBoxes, NearPartsFourAtATimeAreTheOneBoxTests) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(0, 1);
    for (std::size_t parts = 1; parts <= 9; ++parts) {
        const Boxes prim = random_boxes(rng, static_cast<int>(parts), 0.5, 2.0);
        const PartBoxes boxes(ShapeParts(prim), prim.bounds());
        std::vector<std::uint32_t> near(parts), one_by_one;
        std::size_t kept = 0;
        for (int n = 0; n < 4000; ++n) {
            const Vec3 p = Vec3{u(rng), u(rng), u(rng)} * Vec3{7, 7, 20};
            const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
            const Ray r{p - d * 30.0, d};
            const double g = 0.5 * u(rng), tmin = n % 2 ? 0.0 : 30 * u(rng);
            const std::size_t count = boxes.near_parts(r, g, tmin, near);
            const PartBoxes::Ray4 slabs(boxes, r);
            const PartBoxes::Ray4::Range range = slabs.range(tmin, kInfinity);
            one_by_one.clear();
            for (std::uint32_t i = 0; i < parts; ++i)
                if (slabs.meets_grown(i, range, PartBoxes::Ray4::grow(g))) one_by_one.push_back(i);
            ASSERT_EQ(std::vector<std::uint32_t>(near.begin(), near.begin() + count), one_by_one)
                << parts << " parts, ray " << n;
            kept += count;
        }
        EXPECT_GT(kept, 20 * parts);      // parts are met
        EXPECT_LT(kept, 4000 * parts);    // and left out
    }
}

// Primitives of more than kTreeFrom parts are searched through a tree of their boxes: the
// parts it keeps, in order, are those of the flat scan (every four boxes tested), for rays from
// near and very far, grazing or inside the boxes, along axes, and with growths from nothing to
// more than the box.
TEST(PartBoxes, NearPartsThroughTheTreeAreTheFlatScans) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    std::size_t through_tree = 0;
    std::size_t few = 0, many = 0;  // tree searches finding up to 16 parts (insertion), or more
    for (const int parts : {int(PartBoxes::kTreeFrom) + 1, 100, 1000, 5000}) {
        const Boxes prim = random_boxes(rng, parts, parts > 500 ? 0.1 : 0.4, 1.0);
        const PartBoxes boxes(ShapeParts(prim), prim.bounds(), true);
        std::vector<std::uint32_t> near(prim.parts.size()), flat;
        std::size_t kept = 0;
        for (int n = 0; n < 3000; ++n) {
            const Vec3 p = Vec3{u(rng), u(rng), u(rng)} * Vec3{7, 7, 20};
            Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
            if (n % 11 == 0) d = {0, 0, 1};                       // the double fallback
            const double dist = std::pow(10.0, 12 * u(rng) - 2);  // inside the box to 1e10 away
            const Ray r{p - d * dist, d * std::pow(10.0, 4 * u(rng) - 2)};
            const double g = n % 5 == 0 ? 0.0 : std::pow(10.0, 4 * u(rng) - 3);
            const double tmin = n % 2 ? -kInfinity : dist / length(r.d) * u(rng);
            const std::size_t count = boxes.near_parts(r, g, tmin, near);
            const PartBoxes::Ray4 slabs(boxes, r);
            const PartBoxes::Ray4::Range range = slabs.range(tmin, kInfinity);
            const PartBoxes::Ray4::Grow grow = PartBoxes::Ray4::grow(g);
            flat.clear();
            for (std::uint32_t i = 0; i < prim.parts.size(); ++i) {
                const bool met = slabs.in_float()
                                     ? (slabs.meets_grown4(i / 4, range, grow) >> (i % 4) & 1u)
                                     : slabs.meets_grown(i, range, grow);
                if (met) flat.push_back(i);
            }
            ASSERT_EQ(std::vector<std::uint32_t>(near.begin(), near.begin() + count), flat)
                << parts << " parts, ray " << n;
            kept += count;
            if (slabs.in_float() && slabs.tame(grow)) {
                ++through_tree;
                ++(count <= 16 ? few : many);
            }
        }
        EXPECT_GT(kept, 100u);                           // parts are met
        EXPECT_LT(kept, 3000u * prim.parts.size() / 2);  // and left out
    }
    EXPECT_GT(through_tree, 8000u);
    EXPECT_GT(few, 1000u);
    EXPECT_GT(many, 100u);
}

// Boxes that give the split nothing to choose between (5,000 copies of one box, or boxes nested
// one in the next) still make a tree that answers as the flat scan (and stays shallow enough
// for its search's stack, which a debug build asserts).
TEST(PartBoxes, DegenerateBoxesMakeATreeThatAnswersAsTheFlatScan) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0, 1);
    for (const bool nested : {false, true}) {
        Boxes prim;
        const Vec3 c{3.5, 3.5, 10};
        for (int i = 0; i < 5000; ++i) {
            const double h = nested ? 0.001 * (i + 1) : 0.5;
            prim.parts.push_back({c - Vec3{h, h, h}, c + Vec3{h, h, h}});
        }
        const PartBoxes boxes(ShapeParts(prim), prim.bounds(), true);
        std::vector<std::uint32_t> near(prim.parts.size());
        for (int n = 0; n < 200; ++n) {
            const Vec3 p = c + Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} * 6.0;
            const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
            const Ray r{p - d * 30.0, d};
            const std::size_t count = boxes.near_parts(r, 0.05, 0.0, near);
            const PartBoxes::Ray4 slabs(boxes, r);
            std::vector<std::uint32_t> flat;
            for (std::uint32_t i = 0; i < prim.parts.size(); ++i)
                if (slabs.meets_grown4(i / 4, slabs.range(0.0, kInfinity),
                                       PartBoxes::Ray4::grow(0.05)) >>
                        (i % 4) &
                    1u)
                    flat.push_back(i);
            ASSERT_EQ(std::vector<std::uint32_t>(near.begin(), near.begin() + count), flat)
                << (nested ? "nested" : "copies") << ", ray " << n;
        }
    }
}

// A primitive with a part of unbounded box still builds its tree (the split sorts such a
// part as if centred at 0) and near_parts answers as the flat scan: the part is near every ray.
TEST(PartBoxes, AnUnboundedPartLeavesTheTreeAnsweringAsTheFlatScan) {
    std::mt19937 rng(19);
    std::uniform_real_distribution<double> u(0, 1);
    class Unbounded final : public BoxParts {
    public:
        using BoxParts::part_bounds;
        Boxes inner;
        Bounds3 bounds() const override { return inner.bounds(); }
        std::size_t part_count() const override { return inner.parts.size() + 1; }
        Bounds3 part_bounds(std::size_t i) const override {
            return i == 7 ? Bounds3{Vec3{-kInfinity, 0, 0}, Vec3{kInfinity, 1, 1}}
                          : inner.parts[i < 7 ? i : i - 1];
        }
    } prim;
    prim.inner = random_boxes(rng, 60, 0.4, 1.0);
    const PartBoxes boxes(ShapeParts(prim), prim.bounds(), true);
    std::vector<std::uint32_t> near(prim.part_count());
    for (int n = 0; n < 500; ++n) {
        const Vec3 p = Vec3{u(rng), u(rng), u(rng)} * Vec3{7, 7, 20};
        const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        const Ray r{p - d * 30.0, d};
        const std::size_t count = boxes.near_parts(r, 0.1, 0.0, near);
        const PartBoxes::Ray4 slabs(boxes, r);
        std::vector<std::uint32_t> flat;
        for (std::uint32_t i = 0; i < prim.part_count(); ++i)
            if (slabs.meets_grown4(i / 4, slabs.range(0.0, kInfinity),
                                   PartBoxes::Ray4::grow(0.1)) >>
                    (i % 4) &
                1u)
                flat.push_back(i);
        ASSERT_EQ(std::vector<std::uint32_t>(near.begin(), near.begin() + count), flat) << n;
        EXPECT_TRUE(std::find(flat.begin(), flat.end(), 7u) != flat.end());
    }
}

// Ten spheres of radius r up the box, wandering in x and y at frequencies fx and fy, chained
// by cylinders of the same radius.
struct WavyHair {
    std::vector<ChainSphere> spheres;
    std::vector<ChainCylinder> cylinders;
    WavyHair(double fx, double fy, double r) {
        for (int i = 0; i < 10; ++i) {
            spheres.push_back({{3.5 + std::sin(i * fx), 3.5 + std::cos(i * fy), 1 + 1.8 * i}, r});
            if (i > 0) cylinders.push_back({i - 1, i, r});
        }
    }
};

// A wavy hair as a chain, with its parts' boxes in the Plate 4 hair's lattice box.
struct WavyHairBoxes {
    WavyHair wavy;
    ChainShape hair;
    PartBoxes boxes;
    WavyHairBoxes(double fx, double fy, double r)
        : wavy(fx, fy, r),
          hair(wavy.spheres, wavy.cylinders),
          boxes(ShapeParts(hair), {{0, 0, 0}, {7, 7, 20}}) {}
};

// A union's first crossing over its parts, box-tested first (what filtered lattices blend in),
// is the primitive's own, bit for bit: the same t, part and stored point, and none where it has
// none; rays aimed at joints (where a sphere and its cylinders meet) and grazing the hair.
TEST(PartBoxes, FirstCrossingOverAllPartsIsTheUnions) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0, 1);
    const WavyHairBoxes h(0.7, 0.5, 0.3);
    const auto& [spheres, hair, boxes] = std::tie(h.wavy.spheres, h.hair, h.boxes);
    std::vector<std::uint32_t> all(hair.part_count());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    int hits = 0;
    for (int n = 0; n < 20000; ++n) {
        const ChainSphere& aim = spheres[static_cast<std::size_t>(n) % spheres.size()];
        // At a joint's centre, on its surface, or near the hair.
        const Vec3 jitter = Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} * (n % 3 == 0 ? 0.0 : 1.2);
        const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        const Ray r{aim.center + jitter - d * (1 + 50 * u(rng)), d * (0.1 + 3 * u(rng))};
        const double tmin = n % 4 == 0 ? 0.5 : 0.0, tmax = n % 5 == 0 ? 2.0 : kInfinity;
        Crossing want, got;
        const bool w = hair.intersect(r, tmin, tmax, want);
        const bool g = boxes.first_crossing(ShapeParts(hair), all, r, tmin, tmax, got);
        ASSERT_EQ(w, g) << "ray " << n;
        if (!w) continue;
        ++hits;
        ASSERT_EQ(want.t, got.t) << "ray " << n;
        ASSERT_EQ(want.part, got.part) << "ray " << n;
        ASSERT_TRUE(want.stored.p == got.stored.p && want.stored.n == got.stored.n) << "ray " << n;
    }
    EXPECT_GT(hits, 5000);
}

// Lists of every length, the short ones answered without boxes (kFewParts) and the long ones
// with them, answer as a loop over the listed parts: the same crossing, bit for bit, and the
// same occlusion.
TEST(PartBoxes, ListsOfEveryLengthAnswerAsALoopOverTheirParts) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    const WavyHairBoxes h(0.9, 0.4, 0.35);
    const auto& [spheres, hair, boxes] = std::tie(h.wavy.spheres, h.hair, h.boxes);
    int boxed_hits = 0, short_hits = 0;
    for (int n = 0; n < 20000; ++n) {
        std::vector<std::uint32_t> listed;
        const std::size_t length = 1 + static_cast<std::size_t>(n) % hair.part_count();
        for (std::uint32_t i = 0; i < hair.part_count(); ++i)
            if (u(rng) < double(length) / double(hair.part_count())) listed.push_back(i);
        if (listed.empty())
            listed.push_back(static_cast<std::uint32_t>(n % int(hair.part_count())));
        const ChainSphere& aim = spheres[static_cast<std::size_t>(n) % spheres.size()];
        const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        const Vec3 jitter = Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} * 1.2;
        const Ray r{aim.center + jitter - d * (1 + 30 * u(rng)), d * (0.1 + 3 * u(rng))};
        const double tmin = n % 4 == 0 ? 0.5 : 0.0, tmax = n % 5 == 0 ? 3.0 : kInfinity;
        // The loop written out: each listed part in order, the range narrowed by each hit.
        Crossing want, got;
        bool w = false, blocks = false;
        double until = tmax;
        for (const std::uint32_t part : listed) {
            Crossing c;
            if (hair.intersect_part(part, r, tmin, until, c)) want = c, until = c.t, w = true;
            blocks = blocks || hair.occluded_part(part, r, tmin, tmax);
        }
        ASSERT_EQ(w, boxes.first_crossing(ShapeParts(hair), listed, r, tmin, tmax, got)) << "ray " << n;
        ASSERT_EQ(blocks, boxes.any_occludes(ShapeParts(hair), listed, r, tmin, tmax)) << "ray " << n;
        if (!w) continue;
        (listed.size() > PartBoxes::kFewParts ? boxed_hits : short_hits) += 1;
        ASSERT_EQ(want.t, got.t) << "ray " << n;
        ASSERT_EQ(want.part, got.part) << "ray " << n;
    }
    EXPECT_GT(boxed_hits, 1000);  // crossings found through the boxes
    EXPECT_GT(short_hits, 1000);  // and without them
}

}  // namespace
}  // namespace lat
