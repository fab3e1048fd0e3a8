// A coverage table's count of sub-rays a pair: chosen per primitive (64, or fewer for a
// primitive costly to intersect), recorded in the payload and the table's name, and never read
// as another count.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>

#include "coverage_checks.h"
#include "hook_primitive.h"
#include "lattice/cache/table_build.h"
#include "lattice/cache/table_cache.h"
#include "lattice/coverage.h"
#include "lattice/encoding.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

using test::hook;

// Every box of the cell's n equal boxes of each power-of-two shape holds one shift: each count
// samples the cell evenly (the tiling property of lattice/coverage.h's header).
TEST(CoverageCount, EveryCountsOffsetsAreANet) {
    for (const int n : {1, 4, 16, kCostlyRays, 32, kCoverageRays, 256}) {
        const auto& off = coverage_offsets(n);
        ASSERT_EQ(off.size(), static_cast<std::size_t>(n));
        for (int cols = 1; cols <= n; cols *= 2) {
            const int rows = n / cols;
            std::set<std::pair<int, int>> boxes;
            for (const auto& o : off) {
                ASSERT_GT(o[0], -0.5);
                ASSERT_LT(o[0], 0.5);
                ASSERT_GT(o[1], -0.5);
                ASSERT_LT(o[1], 0.5);
                boxes.insert({static_cast<int>((o[0] + 0.5) * cols),
                              static_cast<int>((o[1] + 0.5) * rows)});
            }
            EXPECT_EQ(boxes.size(), static_cast<std::size_t>(n)) << n << " shifts, " << cols << " columns";
        }
    }
    // The count of tables before counts were chosen keeps its offsets (and its tables their bytes).
    EXPECT_EQ(coverage_offsets(64)[5][0], (5 + 0.5) / 64 - 0.5);
    EXPECT_EQ(coverage_offsets(64)[5][1], 0.625 + 0.5 / 64 - 0.5);
    EXPECT_FALSE(valid_coverage_rays(0));
    EXPECT_FALSE(valid_coverage_rays(24));
    EXPECT_FALSE(valid_coverage_rays(2048));
}

// With 16 sub-rays a pair, the build's culled coverage is the definition's to the bit, and its
// shares are multiples of 1/16 of the pair's own sub-rays.
TEST(CoverageCount, SixteenSubRaysBuildAsTheDefinition) {
    TableContext ctx = test::kHookContext;
    ctx.coverage_rays = 16;
    const std::vector<CoverageSample> all = rasterize_coverage(ctx, false);
    ASSERT_GT(all.size(), 500u);
    int partial = 0;
    for (std::size_t i = 0; i < all.size(); i += 7) {
        const CoverageSample ref = pair_coverage(ctx, all[i].a, all[i].b);
        ASSERT_EQ(all[i].alpha, ref.alpha) << all[i].a << " -> " << all[i].b;
        ASSERT_EQ(all[i].t, ref.t);
        partial += ref.alpha < 1;
    }
    EXPECT_GT(partial, 20);
    // Fewer sub-rays give other shares than 64 somewhere.
    const std::vector<CoverageSample> sixty_four = rasterize_coverage(test::kHookContext, false);
    EXPECT_NE(all.size(), sixty_four.size());
}

// A table of 16 sub-rays a pair is read back with them, and says so.
TEST(CoverageCount, ATableOfSixteenIsReadBack) {
    TableContext ctx = test::kHookContext;
    ctx.coverage_rays = 16;
    const test::BuiltCoverageTable b = test::expect_table_answers_coverage(ctx);
    EXPECT_NE(b.table->details().find("16 sub-rays a pair"), std::string::npos) << b.table->details();
    // Opened on its own (inspect), whatever it records is its count.
    TableContext any = ctx;
    any.coverage_rays = kAnyCoverageRays;
    const Encoding& e = find_encoding("coverage");
    EXPECT_NE(e.open(b.payload.data(), b.payload.size(), b.rasterized.hits, any)->details().find("16 sub-rays"),
              std::string::npos);
}

std::string open_error(const ByteBuffer& payload, std::uint64_t hits, const TableContext& ctx) {
    try {
        find_encoding("coverage").open(payload.data(), payload.size(), hits, ctx);
    } catch (const std::exception& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(CoverageCount, AnotherCountsPayloadIsRefused) {
    const Encoding& e = find_encoding("coverage");
    const RasterizeResult r = rasterize(test::kHookContext);
    const ByteBuffer payload = e.build(r.raw, test::kHookContext, {});  // 64 sub-rays
    TableContext sixteen = test::kHookContext;
    sixteen.coverage_rays = 16;
    EXPECT_NE(open_error(payload, r.hits, sixteen).find("sampled with 64 sub-rays a pair where 16"),
              std::string::npos)
        << open_error(payload, r.hits, sixteen);
    EXPECT_EQ(open_error(payload, r.hits, test::kHookContext), "(no error)");
}

// A hook (a chain: cheap) and a row of six small tori (a CSG of cost 72, past kMaxExactCost).
constexpr const char* kTwoPrimitives = R"({
  "camera": {"eye": [1, -3, 1], "look_at": [1, 0.5, 1], "up": [0, 0, 1], "fov_y_deg": 30,
             "width": 16, "height": 16},
  "background": [0, 0, 0], "ambient": [1, 1, 1], "shadows": false, "lights": [],
  "materials": {"w": {"color": [1, 1, 1], "ka": 1, "kd": 0, "ks": 0, "shininess": 1}},
  "primitives": {
    "hair": {"spheres": [[1, 0.5, 0.5, 0.2], [1, 0.5, 1.5, 0.2]], "cylinders": [[0, 1, 0.2]],
             "lattice": {"sigma": 1, "cells": [2, 1, 2]}},
    "row": {"object": {"type": "csg", "op": "union", "children": [ROW]},
            "lattice": {"sigma": 1, "cells": [2, 1, 2]}}},
  "objects": [{"type": "instance", "primitive": "hair", "material": "w"},
              {"type": "instance", "primitive": "row", "material": "w"}]
})";

Scene two_primitives(const test::TempDir& dir) {
    std::string tori;
    for (int i = 0; i < 6; ++i)
        tori += (i ? ", " : "") + std::string(R"({"type": "torus", "center": [)") +
                std::to_string(0.4 + 0.24 * i) +
                R"(, 0.5, 1], "axis": [0, 0, 1], "major_radius": 0.3, "minor_radius": 0.05})";
    std::string text = kTwoPrimitives;
    text.replace(text.find("ROW"), 3, tori);
    const std::string path = (dir.path() / "two.json").string();
    std::ofstream(path) << text;
    return load_scene(path);
}

TablePlan coverage_plan(const Scene& s, std::size_t i) {
    TableSpec spec;
    spec.encoding = "coverage";
    return plan_table(s.primitives.at(i), spec, s.file);
}

// The count is the primitive's: 64 for the chain, kCostlyRays for the costly CSG, in the plan's
// context, its header and its table's name; other encodings keep their names.
TEST(CoverageCount, APlanTakesItsPrimitivesCount) {
    test::TempDir dir;
    const Scene s = two_primitives(dir);
    ASSERT_EQ(s.primitives.at(1).name, "row");
    const TablePlan hair = coverage_plan(s, 0), row = coverage_plan(s, 1);
    EXPECT_EQ(hair.context.coverage_rays, kCoverageRays);
    EXPECT_EQ(row.context.coverage_rays, kCostlyRays);
    EXPECT_EQ(row.header.coverage_rays, kCostlyRays);
    EXPECT_EQ(coverage_rays_for(*s.primitives.at(1).shape), kCostlyRays);
    EXPECT_EQ(coverage_rays_for(hook()), kCoverageRays);
}

// A cached table sampled with 64 sub-rays a pair where the plan asks for 16 (a file of another
// count under the plan's name) is refused, saying why, never read as the plan's.
TEST(CoverageCount, TheCacheRefusesAnotherCount) {
    test::TempDir dir;
    const Scene s = two_primitives(dir);
    const TablePlan row = coverage_plan(s, 1);
    ASSERT_EQ(row.context.coverage_rays, 16);
    TableContext sixty_four = row.context;
    sixty_four.coverage_rays = kCoverageRays;
    const RasterizeResult r = rasterize(sixty_four);
    TableHeader h = row.header;
    h.pairs = r.pairs_eq2;
    h.entries = r.hits;
    const TableCache cache(dir.path().string());
    write_table_file(cache.path_for(row), h, find_encoding("coverage").build(r.raw, sixty_four, {}));
    std::string error = "(no error)";
    try {
        cache.get(row, false);
    } catch (const InputError& e) {
        error = e.what();
    }
    EXPECT_NE(error.find("sampled with 64 sub-rays a pair where 16 are asked for"), std::string::npos)
        << error;
    // Built by the cache, it has the plan's count.
    std::filesystem::remove(cache.path_for(row));
    const TableCache::Entry e = cache.get(row, false);
    EXPECT_TRUE(e.built);
    EXPECT_NE(e.table->details().find("16 sub-rays a pair"), std::string::npos);
}

// The level budget's estimate of a build counts its sub-rays: with 16 a pair, the work of 16
// plus the pair's own (kPairOverheadRays), against 64 plus that.
TEST(CoverageCount, TheEstimateCountsSubRays) {
    TableContext sixteen = test::kHookContext;
    sixteen.coverage_rays = 16;
    const double w16 = coverage_work(sixteen), w64 = coverage_work(test::kHookContext);
    ASSERT_GT(w16, 0);
    EXPECT_DOUBLE_EQ(w64 / w16, (64 + kPairOverheadRays) / (16 + kPairOverheadRays));
    EXPECT_DOUBLE_EQ(coverage_cpu_seconds(sixteen), w16 / kCoverageTestsPerCpuSecond);
}

}  // namespace
}  // namespace lat
