// Snapping in float (lattice/float_snap.h) gives the double-precision snap's grid points bit for
// bit, or says it is unsure: checked on random rays and on rays built to sit on the edge of
// every decision the snap makes (points a hair from half a cell, entries on the box's edges
// and corners, lines grazing the box, directions with tiny or zero components, far origins).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "lattice/float_snap.h"
#include "lattice/lattice_shape.h"

namespace lat {
namespace {

struct Tally {
    long pairs = 0, misses = 0, unsure = 0;
    long total() const { return pairs + misses + unsure; }
};

// Checks one ray (lattice units; the frame's cell is 1) against the double snap.
void check(const LatticeFrame& frame, const std::array<int, 3>& cells, Vec3 o, Vec3 d,
           Tally& tally) {
    GridPoint pa, pb;
    const FloatSnap f = snap_float(o, d, cells, pa, pb);
    LatticeFrame::Snap ref;
    const bool meets = frame.snap_double({o, d}, ref);
    LatticeFrame::Snap s;
    ASSERT_EQ(frame.snap({o, d}, s), meets);
    if (meets) {
        ASSERT_TRUE(s.a == ref.a && s.b == ref.b && s.pa == ref.pa && s.pb == ref.pb);
    }
    switch (f) {
        case FloatSnap::kUnsure: ++tally.unsure; return;
        case FloatSnap::kMiss:
            ++tally.misses;
            ASSERT_FALSE(meets) << "o " << o.x << ' ' << o.y << ' ' << o.z << " d " << d.x << ' '
                                << d.y << ' ' << d.z;
            return;
        case FloatSnap::kPair:
            ++tally.pairs;
            ASSERT_TRUE(meets && pa == ref.pa && pb == ref.pb)
                << "o " << o.x << ' ' << o.y << ' ' << o.z << " d " << d.x << ' ' << d.y << ' '
                << d.z << ": float (" << pa.x << ' ' << pa.y << ' ' << pa.z << ") -> (" << pb.x
                << ' ' << pb.y << ' ' << pb.z << "), double (" << ref.pa.x << ' ' << ref.pa.y
                << ' ' << ref.pa.z << ") -> (" << ref.pb.x << ' ' << ref.pb.y << ' ' << ref.pb.z
                << ")";
    }
}

const std::array<std::array<int, 3>, 6> kCells = {
    {{8, 8, 8}, {7, 7, 20}, {5, 3, 7}, {1, 1, 1}, {256, 3, 40}, {1024, 1025, 3}}};

LatticeFrame frame_for(const std::array<int, 3>& cells) {
    return LatticeFrame(TableContext{cells, 1.0, 1.0, nullptr}, kInfinity);
}

Vec3 cells_vec(const std::array<int, 3>& n) {
    return {double(n[0]), double(n[1]), double(n[2])};
}

// A point on a random face of the box, its two free coordinates drawn by pick(extent).
template <class Pick>
Vec3 face_point(const std::array<int, 3>& n, std::mt19937_64& rng, Pick pick) {
    const int axis = static_cast<int>(rng() % 3);
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
        const auto uk = static_cast<std::size_t>(k);
        p[uk] = k == axis ? (rng() % 2 ? double(n[uk]) : 0.0) : pick(n[uk]);
    }
    return p;
}

TEST(FloatSnap, RandomRaysFromNearAndFarAgreeAndAreRarelyUnsure) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (const auto& n : kCells) {
        const LatticeFrame frame = frame_for(n);
        const Vec3 size = cells_vec(n);
        const double diag = length(size);
        for (const double reach : {0.5, 3.0, 100.0, 1e4}) {
            Tally tally;
            for (int i = 0; i < 100000; ++i) {
                const Vec3 o = size * 0.5 + Vec3{unit(rng), unit(rng), unit(rng)} * (reach * diag);
                const Vec3 target =
                    size * 0.5 + Vec3{unit(rng) * size.x, unit(rng) * size.y, unit(rng) * size.z} * 0.6;
                const Vec3 d = (target - o) * std::exp(3 * unit(rng));  // any length
                check(frame, n, o, d, tally);
                if (HasFatalFailure()) return;
            }
            // The fast path answers nearly every ray from a scene's distances (its margin grows
            // with the distance: from 100 diagonals away up to a tenth of the rays are left to double).
            const double rate = double(tally.unsure) / double(tally.total());
            std::printf("%dx%dx%d, %g diagonals: %.5f unsure\n", n[0], n[1], n[2], reach, rate);
            // (A lattice of 1024 cells a side is left to double 4 % of the time even so.)
            if (reach <= 3 && n[0] <= 256) {
                EXPECT_LT(rate, 0.01) << n[0] << 'x' << n[1] << 'x' << n[2];
            }
            if (reach <= 100) {
                EXPECT_GT(tally.pairs, 0);
            }
        }
    }
}

// Entry and exit points a hair (0 to 1e-3 cells, down to single ulps) from half a cell, where
// rounding turns: the double snap's own rounding decides, and the float one must follow or
// say it is unsure.
TEST(FloatSnap, PointsAHairFromHalfACellAgree) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> unit(0, 1);
    const double hairs[] = {0, 1e-16, 1e-12, 1e-9, 1e-7, 3e-7, 1e-6, 1e-5, 1e-4, 1e-3};
    for (const auto& n : kCells) {
        const LatticeFrame frame = frame_for(n);
        Tally tally;
        for (int i = 0; i < 40000; ++i) {
            // Each free coordinate a hair from half a cell, or anywhere (so that some rays have
            // a single coordinate on the edge of a decision, and the float snap answers them).
            auto near_half = [&](int extent) {
                if (rng() % 2) return unit(rng) * extent;
                const double h = hairs[rng() % std::size(hairs)] * (rng() % 2 ? 1 : -1);
                return std::clamp(double(rng() % static_cast<unsigned>(extent + 1)) - 0.5 + h, 0.0,
                                  double(extent));
            };
            const Vec3 a = face_point(n, rng, near_half), b = face_point(n, rng, near_half);
            if (a == b) continue;
            // The origin before, inside or after the box, near or far.
            const double s = (unit(rng) * 2 - 0.5) * std::pow(10.0, 3 * unit(rng));
            const Vec3 d = (b - a) * std::exp(2 * unit(rng) - 1);
            check(frame, n, a - d * s, d, tally);
            if (HasFatalFailure()) return;
        }
        // Many of these rays are within the margin of a tie, left to double; not all.
        std::printf("%dx%dx%d: %ld pairs, %ld misses, %ld unsure\n", n[0], n[1], n[2],
                    tally.pairs, tally.misses, tally.unsure);
        EXPECT_GT(tally.pairs, 0);
    }
}

// Entries and exits on and around the box's edges and corners, and lines that graze it (their
// chord a hair long, or a hair short of meeting it): the entry axis is nearly tied, or the
// meet/miss decision is.
TEST(FloatSnap, EdgesCornersAndGrazingLinesAgree) {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> unit(-1, 1);
    const double hairs[] = {0, 1e-15, 1e-10, 1e-7, 1e-6, 1e-4, 1e-2};
    for (const auto& n : kCells) {
        const LatticeFrame frame = frame_for(n);
        const Vec3 size = cells_vec(n);
        Tally tally;
        for (int i = 0; i < 40000; ++i) {
            // A corner or edge point (each coordinate at 0 or n, or free), moved a hair.
            Vec3 p;
            for (std::size_t k = 0; k < 3; ++k) {
                const unsigned pick = rng() % 3;
                const double h = hairs[rng() % std::size(hairs)] * unit(rng);
                p[k] = (pick == 0 ? 0.0 : pick == 1 ? size[k] : (unit(rng) + 1) * 0.5 * size[k]) + h;
            }
            const Vec3 d = Vec3{unit(rng), unit(rng), unit(rng)} * std::exp(3 * unit(rng));
            const double s = unit(rng) * std::pow(10.0, 2 * unit(rng));
            check(frame, n, p - d * s, d, tally);
            if (HasFatalFailure()) return;
        }
        EXPECT_GT(tally.pairs + tally.misses, tally.total() / 2);
    }
}

// Directions with a zero, denormal or tiny component, and origins far away: unsure is allowed,
// a wrong pair is not.
TEST(FloatSnap, TinyComponentsAndFarOriginsAgree) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> unit(-1, 1);
    const double tiny[] = {0.0, -0.0, 1e-300, 1e-45, 1e-39, 1e-30, 1e-12, 1e-8, 1e-5,
                           // and huge: beyond a float, or with a denormal float reciprocal
                           1e39, 1e38, 3e37};
    const double far[] = {1, 1e3, 1e6, 1e9, 1e12, 1e30};
    for (const auto& n : kCells) {
        const LatticeFrame frame = frame_for(n);
        const Vec3 size = cells_vec(n);
        Tally tally;
        for (int i = 0; i < 40000; ++i) {
            const Vec3 target{(unit(rng) + 1) * 0.5 * size.x, (unit(rng) + 1) * 0.5 * size.y,
                              (unit(rng) + 1) * 0.5 * size.z};
            Vec3 d{unit(rng), unit(rng), unit(rng)};
            d[rng() % 3] = tiny[rng() % std::size(tiny)] * (rng() % 2 ? 1 : -1);
            if (rng() % 2) d[rng() % 3] = tiny[rng() % std::size(tiny)];
            if (d == Vec3{}) continue;
            const double s = far[rng() % std::size(far)] * unit(rng);
            check(frame, n, target - d * s, d, tally);
            if (HasFatalFailure()) return;
        }
        EXPECT_GT(tally.pairs, 0);
    }
}

// Origins 1e6 to 1e13 cells away with ordinary directions, aimed at the box or beside it
// (large lattices too): the slab parameters are as large as they get against the box, and the
// meet-or-miss decision rests on the bound the most (points are left to double from there).
TEST(FloatSnap, FarOriginsWithOrdinaryDirectionsAgree) {
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (const auto& n : kCells) {
        const LatticeFrame frame = frame_for(n);
        const Vec3 size = cells_vec(n);
        Tally tally;
        for (int i = 0; i < 40000; ++i) {
            const Vec3 target = size * 0.5 + Vec3{unit(rng) * size.x, unit(rng) * size.y,
                                                  unit(rng) * size.z};
            const Vec3 d = Vec3{unit(rng), unit(rng), unit(rng)} * std::pow(10.0, 6 * unit(rng));
            const double far = std::pow(10.0, 6 + 7 * (unit(rng) + 1) / 2) / length(d);
            check(frame, n, target - d * far, d, tally);
            if (HasFatalFailure()) return;
        }
        EXPECT_GT(tally.misses, 200) << n[0] << 'x' << n[1] << 'x' << n[2];
    }
}

}  // namespace
}  // namespace lat
