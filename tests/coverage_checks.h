#pragma once
// Checks the coverage tests share.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "lattice/coverage.h"
#include "lattice/encoding.h"
#include "lattice/octahedral.h"
#include "lattice/rasterizer.h"

namespace lat::test {

// A coverage table built for a test, with what it reads (the payload must outlive it).
struct BuiltCoverageTable {
    RasterizeResult rasterized;
    ByteBuffer payload;
    std::unique_ptr<LatticeTable> table;
};

// How far a coverage table's answer may lie from the sample it keeps: half a step of its
// alpha (1/255) and mean t (1/511); for its mean normal's direction the worst angle of 6 + 6-bit
// octahedral codes chosen as the nearest of four (2.56 degrees; 2.6 here), and for its
// spread, sqrt(1 - length^2), half a step of 1/7 (and of the sample's own 1/255).
inline constexpr double kStoredAlphaError = 0.5 / 255 + 1e-12;
inline constexpr double kStoredTError = 0.5 / 511 + 1e-12;
inline constexpr double kStoredNormalDegrees = 2.6;
inline constexpr double kStoredSpreadError = 0.5 / 7 + 0.5 / 255 + 1e-9;

// Checks that a table's answer is the sample's within those steps.
inline void expect_within_quantisation(const CoverageHit& h, const CoverageSample& c) {
    EXPECT_NEAR(h.alpha, c.alpha, kStoredAlphaError) << c.a << " -> " << c.b;
    EXPECT_NEAR(h.t, c.t, kStoredTError) << c.a << " -> " << c.b;
    const Vec3 n = oct_decode({c.nu, c.nv}, kRawNormalBits);
    // Normals that cancel (a bundle grazing both sides of a thin part) have a mean of length 0,
    // and no direction to check.
    const double len = length(h.normal);
    if (len > 0) {
        EXPECT_GE(dot(h.normal / len, n), std::cos(kStoredNormalDegrees * std::numbers::pi / 180))
            << c.a << " -> " << c.b;
    }
    EXPECT_NEAR(std::sqrt(std::max(0.0, 1 - len * len)), c.spread / 255.0, kStoredSpreadError)
        << c.a << " -> " << c.b;
}

// Builds the coverage table of ctx's lattice and checks that it answers every pair's coverage
// as rasterize_coverage computes it (to its quantisation).
inline BuiltCoverageTable expect_table_answers_coverage(const TableContext& ctx) {
    const Encoding& e = find_encoding("coverage");
    BuiltCoverageTable b{rasterize(ctx), {}, nullptr};
    b.payload = e.build(b.rasterized.raw, ctx, {});
    b.table = e.open(b.payload.data(), b.payload.size(), b.rasterized.hits, ctx);
    for (const CoverageSample& c : rasterize_coverage(ctx, false)) {
        CoverageHit h;
        EXPECT_TRUE(b.table->coverage(c.a, c.b, h));
        expect_within_quantisation(h, c);
    }
    return b;
}

}  // namespace lat::test
