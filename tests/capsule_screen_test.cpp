// The capsule screen (geometry/capsule_screen.h) must name every capsule whose own test in
// double accepts a line, however close to its surface the line passes and however far its
// origin lies; and it must reject most lines that pass well clear.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "geometry/capsule_screen.h"
#include "geometry/chain.h"
#include "lattice/lattice_shape.h"

namespace lat {
namespace {

// The line parallel to `line`, shifted across it along e, that c's test (radius `radius`)
// accepts last, within rounding of the capsule's surface; `line` itself if none is found.
Ray grazing(const Capsule& c, double radius, const Ray& line, Vec3 e) {
    const auto kept = [&](double s) { return c.meets_line(line.o + e * s, line.d, radius); };
    double in = 0, out = 100;
    if (!kept(in) || kept(out)) return line;
    for (int k = 0; k < 90; ++k) {
        const double mid = 0.5 * (in + out);
        (kept(mid) ? in : out) = mid;
    }
    return {line.o + e * in, line.d};
}

struct Lines {
    std::mt19937 rng{29};
    std::uniform_real_distribution<double> u{-1, 1};
    Vec3 random_unit() { return normalize(Vec3{u(rng), u(rng), u(rng)}); }
};

// Random sets of 1 to 32 capsules (ends over a box 20 wide, radii 0.05 to 3), lines through
// random points near them with origins 5, 10^4, 10^9 and 10^13 away and directions of lengths
// 10^-3 to 10^3, half of them grazing a capsule within rounding (found by bisection on its
// own test), with and without a narrower radius.
TEST(CapsuleScreen, NamesEveryCapsuleItsOwnTestAccepts) {
    Lines g;
    std::uniform_real_distribution<double> unit(0, 1);
    long accepted = 0, left_out = 0, tested = 0;
    for (int set = 0; set < 300; ++set) {
        const std::size_t n = 1 + static_cast<std::size_t>(set) % CapsuleScreen::kMaxCapsules;
        std::vector<Capsule> caps;
        double rmin = 10;
        for (std::size_t k = 0; k < n; ++k) {
            const Vec3 a{10 * g.u(g.rng), 10 * g.u(g.rng), 10 * g.u(g.rng)};
            const Vec3 b = set % 7 == 0 ? a : a + g.random_unit() * (4 * unit(g.rng));
            caps.push_back({a, b, 0.05 + 3 * unit(g.rng)});
            rmin = std::min(rmin, caps.back().r);
        }
        const CapsuleScreen screen(caps);
        ASSERT_FALSE(screen.empty());
        for (int l = 0; l < 400; ++l) {
            const double narrower = l % 3 == 0 ? rmin * unit(g.rng) : 0.0;
            const Vec3 d = g.random_unit() * std::pow(10.0, 6 * unit(g.rng) - 3);
            const double far = l % 4 == 0 ? 1e13 : l % 4 == 1 ? 1e9 : l % 4 == 2 ? 1e4 : 5.0;
            const Vec3 p{12 * g.u(g.rng), 12 * g.u(g.rng), 12 * g.u(g.rng)};
            Ray line{p - normalize(d) * far, d};
            if (l % 2 == 0) {
                const Capsule& c = caps[static_cast<std::size_t>(l / 2) % n];
                Vec3 e, f;
                orthonormal_basis(normalize(d), e, f);
                const double t = 6.283185307179586 * unit(g.rng);
                line = grazing(c, c.r - narrower, {c.a + (c.b - c.a) * unit(g.rng) - normalize(d) * far, d},
                               e * std::cos(t) + f * std::sin(t));
            }
            const std::uint32_t bits = screen.may_meet(line.o, line.d, narrower);
            for (std::size_t k = 0; k < n; ++k) {
                ++tested;
                const bool named = (bits >> k) & 1;
                if (caps[k].meets_line(line.o, line.d, caps[k].r - narrower)) {
                    ++accepted;
                    ASSERT_TRUE(named) << "set " << set << " line " << l << " capsule " << k;
                } else if (!named) {
                    ++left_out;
                }
            }
        }
    }
    EXPECT_GT(accepted, 20000);
    EXPECT_GT(left_out, tested / 2);  // it screens: most capsules are missed by most lines
}

TEST(CapsuleScreen, TooManyOrNoneNameEveryCapsule) {
    EXPECT_TRUE(CapsuleScreen(std::span<const Capsule>{}).empty());
    EXPECT_TRUE(CapsuleScreen().empty());
    std::vector<Capsule> many(CapsuleScreen::kMaxCapsules + 1, Capsule{{0, 0, 0}, {1, 0, 0}, 0.1});
    const CapsuleScreen screen(many);
    EXPECT_TRUE(screen.empty());
    EXPECT_EQ(screen.may_meet({0, 50, 0}, {0, 0, 1}), ~std::uint32_t{0});
}

// Lines the float screen cannot measure (no direction, a non-finite one, an origin too far
// for its margin) get every capsule the screen holds, and no bit past them: callers index
// their capsules by the bits.
TEST(CapsuleScreen, UnmeasurableLinesNameTheCapsulesHeldAndNoMore) {
    const std::vector<Capsule> three(3, Capsule{{0, 0, 0}, {1, 0, 0}, 0.1});
    const CapsuleScreen screen(three);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(screen.may_meet({0, 5, 0}, {0, 0, 0}), 0b111u);
    EXPECT_EQ(screen.may_meet({0, 5, 0}, {nan, 0, 1}), 0b111u);
    EXPECT_EQ(screen.may_meet({0, 1e36, 0}, {0, 0, 1}), 0b111u);
}

// A hair's lattice frame answers cull_meets_any as the loop over its cull parts does, on lines
// grazing its capsules and on random ones.
TEST(CapsuleScreen, LatticeFramesAnswerAsTheirPartsDo) {
    const ChainShape hair{{{{3.5, 3.5, 0.5}, 0.5}, {{3.8, 4.1, 2.6}, 0.5}, {{2.8, 4.7, 4.7}, 0.5},
                           {{1.5, 3.5, 6.8}, 0.5}, {{2.2, 1.2, 8.9}, 0.5}, {{5.0, 0.9, 11.1}, 0.5}},
                          {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}, {3, 4, 0.5}, {4, 5, 0.5}}};
    const TableContext ctx{{7, 7, 12}, 1.0, 1.0, &hair};
    const LatticeFrame frame(ctx, 0.9, 0.9);
    ASSERT_GT(frame.cull_count(), 3u);
    Lines g;
    int met = 0, missed = 0;
    for (int l = 0; l < 20000; ++l) {
        const Vec3 d = g.random_unit();
        const Vec3 p{3.5 + 5 * g.u(g.rng), 3.5 + 5 * g.u(g.rng), 6 + 8 * g.u(g.rng)};
        const double far = l % 3 == 0 ? 1e9 : 20.0;
        const double narrower = l % 2 == 0 ? 0.0 : 0.4;
        const Ray r{p - d * far, d};
        bool any = false;
        for (std::size_t i = 0; i < frame.cull_count(); ++i) any = any || frame.cull_meets(i, r, narrower);
        ASSERT_EQ(frame.cull_meets_any(r, narrower), any) << "line " << l;
        (any ? met : missed) += 1;
    }
    EXPECT_GT(met, 2000);
    EXPECT_GT(missed, 2000);
}

}  // namespace
}  // namespace lat
