#pragma once
// Checks the coverage tests share.
#include <gtest/gtest.h>

#include <memory>

#include "lattice/coverage.h"
#include "lattice/encoding.h"
#include "lattice/rasterizer.h"

namespace lat::test {

// A coverage table built for a test, with what it reads (the payload must outlive it).
struct BuiltCoverageTable {
    RasterizeResult rasterized;
    ByteBuffer payload;
    std::unique_ptr<LatticeTable> table;
};

// Builds the coverage table of ctx's lattice and checks that it answers every pair's coverage
// as rasterize_coverage computes it (to its 16-bit quantisation).
inline BuiltCoverageTable expect_table_answers_coverage(const TableContext& ctx) {
    const Encoding& e = find_encoding("coverage");
    BuiltCoverageTable b{rasterize(ctx), {}, nullptr};
    b.payload = e.build(b.rasterized.raw, ctx, {});
    b.table = e.open(b.payload.data(), b.payload.size(), b.rasterized.hits, ctx);
    for (const CoverageSample& c : rasterize_coverage(ctx, false)) {
        CoverageHit h;
        EXPECT_TRUE(b.table->coverage(c.a, c.b, h));
        EXPECT_NEAR(h.alpha, c.alpha, 1e-4);
        EXPECT_NEAR(h.t, c.t, 1e-4);
    }
    return b;
}

}  // namespace lat::test
