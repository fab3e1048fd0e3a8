// The coverage table's pair index (lattice/encodings/coverage/pair_index.h): a bijection between
// the valid pairs of a lattice and the slots they are filed in; and the table read through it
// answers every pair with the values its inputs give (what a * N + b indexing stored).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "coverage_checks.h"
#include "hook_primitive.h"
#include "lattice/coverage.h"
#include "lattice/encoding.h"
#include "lattice/encodings/coverage/coverage_table.h"
#include "lattice/encodings/coverage/pair_index.h"
#include "lattice/octahedral.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

class PairIndexOf : public ::testing::TestWithParam<std::array<int, 3>> {};

TEST_P(PairIndexOf, FilesTheValidPairsOneToOne) {
    const PairIndex index(GetParam());
    const BoundaryGrid& grid = index.grid();
    std::vector<std::uint8_t> used(index.slots(), 0);
    std::uint64_t valid = 0;
    for (std::uint32_t a = 0; a < grid.count(); ++a)
        for (std::uint32_t b = 0; b < grid.count(); ++b) {
            const bool ok = a != b && BoundaryGrid::valid_pair(grid.faces(grid.point(a)),
                                                               grid.faces(grid.point(b)));
            const std::uint64_t s = index.slot(a, b);
            ASSERT_EQ(s != PairIndex::kNone, ok) << a << " " << b;
            if (!ok) continue;
            ++valid;
            ASSERT_LT(s, index.slots());
            ASSERT_EQ(used[s]++, 0) << "two pairs in slot " << s;
            std::uint32_t x = 0, y = 0;
            ASSERT_TRUE(index.pair_at(s, x, y)) << s;
            ASSERT_EQ(x, a);
            ASSERT_EQ(y, b);
        }
    // No other slot decodes to a pair; filed() says the same, a tile at a time or a slot.
    for (std::uint64_t s = 0; s < index.slots(); ++s) {
        std::uint32_t x = 0, y = 0;
        ASSERT_EQ(index.pair_at(s, x, y), used[s] != 0) << s;
        std::array<std::uint64_t, PairIndex::kTileSlots / 64> one{};
        one[s % PairIndex::kTileSlots / 64] = std::uint64_t{1} << (s % 64);
        ASSERT_EQ(index.filed(s / PairIndex::kTileSlots, one), used[s] != 0) << s;
    }
    for (std::uint64_t t = 0; t < index.slots() / PairIndex::kTileSlots; ++t) {
        std::array<std::uint64_t, PairIndex::kTileSlots / 64> all{};
        for (int k = 0; k < PairIndex::kTileSlots; ++k)
            if (used[t * PairIndex::kTileSlots + static_cast<unsigned>(k)])
                all[static_cast<unsigned>(k) / 64] |= std::uint64_t{1} << (k % 64);
        EXPECT_TRUE(index.filed(t, all)) << t;
    }
    EXPECT_EQ(index.slot(grid.count(), 0), PairIndex::kNone);
    EXPECT_EQ(index.slot(0, grid.count()), PairIndex::kNone);
    EXPECT_GT(valid, 0u);
    // About N^2 slots for a lattice of some size: the tiles' padding is up to 3 points along
    // each of 4 coordinates (much of a small lattice), the edges' other faces a few more.
    const double n2 = double(grid.count()) * double(grid.count());
    if (*std::min_element(grid.cells().begin(), grid.cells().end()) >= 7) {
        EXPECT_LE(double(index.slots()), 1.5 * n2);
    }
}

INSTANTIATE_TEST_SUITE_P(Lattices, PairIndexOf,
                         ::testing::Values(std::array<int, 3>{1, 1, 1}, std::array<int, 3>{8, 4, 8},
                                           std::array<int, 3>{3, 5, 2}, std::array<int, 3>{7, 7, 20}));

// The neighbours a blend visits: moving one coordinate of a pair by one stays in its tile
// (slots less than a tile apart) three times in four, tiles being 4 points wide.
TEST(PairIndex, NeighboursInRaySpaceAreNearInMemory) {
    const PairIndex index({16, 16, 16});
    const BoundaryGrid& grid = index.grid();
    int steps = 0, same_tile = 0;
    for (int ay = 1; ay < 16; ++ay)
        for (int az = 1; az < 16; ++az)
            for (int bz = 1; bz < 16; ++bz)
                for (int bx = 1; bx < 16; ++bx) {
                    // Entry on x = 0 (u = y, v = z), exit on y = 16 (u = z, v = x).
                    const int c[4] = {ay, az, bz, bx};
                    auto slot = [&](const int* k) {
                        return index.slot(grid.id({0, k[0], k[1]}), grid.id({k[3], 16, k[2]}));
                    };
                    const std::uint64_t s = slot(c);
                    for (int i = 0; i < 4; ++i) {
                        int d[4] = {c[0], c[1], c[2], c[3]};
                        if (++d[i] > 15) continue;
                        ++steps;
                        same_tile += slot(d) / PairIndex::kTileSlots == s / PairIndex::kTileSlots;
                    }
                }
    EXPECT_GE(same_tile * 4, steps * 3);
}

// The hook's coverage table as built, with what it was built from.
struct HookTable {
    RasterizeResult raster;
    ByteBuffer payload;
};
HookTable hook_table() {
    RasterizeOptions opt;
    opt.keep_hits = true;
    HookTable h{rasterize(test::kHookContext, opt), {}};
    h.payload = find_encoding("coverage").build(h.raster.raw, test::kHookContext, {});
    return h;
}

// Every pair of the hook's table, through the index: its own hit as rasterized and its
// coverage as sampled, quantised as the table keeps them; the other pairs not found.
TEST(PairIndex, TableAnswersEveryPairAsItsInputs) {
    const TableContext& ctx = test::kHookContext;
    const Encoding& e = find_encoding("coverage");
    const HookTable hook = hook_table();
    const RasterizeResult& raster = hook.raster;
    const std::unique_ptr<LatticeTable> table =
        e.open(hook.payload.data(), hook.payload.size(), raster.hits, ctx);
    std::map<std::pair<std::uint32_t, std::uint32_t>, RawHit> hits;
    for (const RawHit& h : raster.raw.flatten()) hits[{h.a, h.b}] = h;
    std::map<std::pair<std::uint32_t, std::uint32_t>, CoverageSample> cover;
    for (const CoverageSample& c : rasterize_coverage(ctx, false)) cover[{c.a, c.b}] = c;
    ASSERT_GT(hits.size(), 1000u);
    ASSERT_GT(cover.size(), hits.size());
    auto t_of = [](double t) { return double(std::lround(std::clamp(t, 0.0, 1.0) * 65534.0)) / 65534.0; };
    const std::uint32_t n = BoundaryGrid(ctx.cells).count();
    for (std::uint32_t a = 0; a < n; ++a)
        for (std::uint32_t b = 0; b < n; ++b) {
            TableHit h;
            const auto hit = hits.find({a, b});
            ASSERT_EQ(table->lookup(a, b, h), hit != hits.end()) << a << " " << b;
            if (hit != hits.end()) {
                EXPECT_EQ(h.t, t_of(hit->second.t));
                EXPECT_EQ(h.normal, oct_decode({hit->second.nu, hit->second.nv}, kRawNormalBits));
            }
            CoverageHit c, many;
            bool found = false;
            // A pair whose own segment hits is stored even if none of its sub-rays does: an
            // alpha of 0 is not an answer.
            const auto cov = cover.find({a, b});
            ASSERT_EQ(table->coverage(a, b, c), cov != cover.end()) << a << " " << b;
            table->coverage_many(&a, &b, 1, &many, &found, true);
            ASSERT_EQ(found, cov != cover.end());
            if (cov == cover.end()) continue;
            CoverageHit kept;
            CoverageTable::unpack_cover(CoverageTable::pack_cover(cov->second), kept, true);
            EXPECT_EQ(c.alpha, kept.alpha);
            EXPECT_EQ(c.t, kept.t);
            EXPECT_EQ(c.normal, kept.normal);
            test::expect_within_quantisation(c, cov->second);
            EXPECT_EQ(many.alpha, c.alpha);
            EXPECT_EQ(many.t, c.t);
            EXPECT_EQ(many.normal, c.normal);
        }
}

// Tables of the layouts before (tag COVER1, pairs indexed a * N + b; COVER2, coverage
// records of 8 bytes; COVER3, records without the normals' spread) are refused, not misread
// (the table cache never opens one: the layout is part of the file names it looks for).
TEST(PairIndex, OlderLayoutIsRefused) {
    const TableContext& ctx = test::kHookContext;
    const Encoding& e = find_encoding("coverage");
    HookTable hook = hook_table();
    const RasterizeResult& raster = hook.raster;
    ByteBuffer& payload = hook.payload;
    ASSERT_EQ(std::memcmp(payload.data(), "COVER4", 6), 0);
    for (const char old : {'1', '2', '3'}) {
        payload.data()[5] = static_cast<std::uint8_t>(old);
        try {
            e.open(payload.data(), payload.size(), raster.hits, ctx);
            FAIL() << "opened";
        } catch (const std::runtime_error& err) {
            EXPECT_NE(std::string(err.what()).find(std::string("older layout (COVER") + old + ")"),
                      std::string::npos)
                << err.what();
        }
    }
    EXPECT_GT(e.layout, 3);
}

}  // namespace
}  // namespace lat
