// Table files with forged headers (checksums recomputed, as a hostile file would have them):
// every field is range-checked and consistent with the others before anything is sized by it.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <cstring>
#include <limits>

#include "geometry/chain.h"
#include "lattice/boundary_grid.h"
#include "lattice/cache/table_cache.h"
#include "lattice/encoding.h"
#include "lattice/encodings/hash14/hash14_table.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "scene/table_metadata.h"
#include "temp_dir.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace lat {
namespace {

class ForgedHeader : public ::testing::Test {
protected:
    ChainShape hook{{{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}},
                    {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}}};
    TableContext ctx{{4, 2, 4}, 1.0, 1.0, &hook};
    test::TempDir dir;
    std::string path = (dir.path() / "t.lht").string();
    TableHeader good;
    ByteBuffer payload;

    void SetUp() override {
        const RasterizeResult r = rasterize(ctx);
        payload = find_encoding("hash14").build(r.raw, ctx, {});
        good.encoding = "hash14";
        good.cells = ctx.cells;
        good.pairs = r.pairs_eq2;
        good.entries = r.hits;
        good.metadata = R"({"primitive": "hook", "definition": {}})";
    }
    // The message of loading a file with this header and payload, "(no error)" if it loads.
    std::string error_with(const TableHeader& h) {
        write_table_file(path, h, payload);
        try {
            load_table_file(path, nullptr, &hook);
        } catch (const InputError& e) {
            return e.what();
        }
        return "(no error)";
    }
    void expect_refused(const TableHeader& h, const std::string& why) {
        const std::string e = error_with(h);
        EXPECT_NE(e.find(path + ": not a valid lattice table: " + why), std::string::npos) << e;
    }
};

TEST_F(ForgedHeader, TheGoodOneLoads) { EXPECT_EQ(error_with(good), "(no error)"); }

TEST_F(ForgedHeader, SigmaInvOutOfRange) {
    for (const int k : {0, -1, 1025, std::numeric_limits<int>::max()}) {
        TableHeader h = good;
        h.sigma_inv = k;
        expect_refused(h, "sigma^-1 = " + std::to_string(k) + " is out of range");
    }
}

TEST_F(ForgedHeader, SigmaAndCellMustBeFiniteAndAgree) {
    for (const double bad : {std::nan(""), 0.0, -1.0, 1e-320, std::numeric_limits<double>::infinity()}) {
        TableHeader h = good;
        h.sigma = bad;
        h.cell = bad;
        expect_refused(h, "sigma must be a positive finite number");
    }
    TableHeader h = good;
    h.cell = 0.5;  // sigma 1, sigma^-1 1
    expect_refused(h, "the cell size is not sigma / sigma^-1");
}

TEST_F(ForgedHeader, CellsMustBeSmallPositiveAndMatchNlp) {
    for (const int c : {0, -4, std::numeric_limits<int>::max()}) {
        TableHeader h = good;
        h.cells[1] = c;
        const std::string e = error_with(h);
        EXPECT_NE(e.find("not a valid lattice table"), std::string::npos) << c << ": " << e;
    }
    TableHeader h = good;
    h.cells = {7, 65535, 20};  // a lattice the payload was not built for
    expect_refused(h, "N_lp does not match the cells");
    h.pairs = static_cast<std::uint64_t>(BoundaryGrid::pair_count(h.cells));
    expect_refused(h, "the hash14 encoding keys at most 65535 boundary points");
    h = good;
    h.entries = h.pairs + 1;
    expect_refused(h, "more stored hits than point pairs");
}

TEST_F(ForgedHeader, Hash14BucketCountCannotOverflowTheSizeCheck) {
    std::uint64_t buckets = std::uint64_t{1} << 63;
    std::memcpy(payload.data(), &buckets, 8);
    expect_refused(good, "hash14: inconsistent payload size");
}

// Overflow entries link back to earlier ones only (as the build lays them out), so no chain
// can loop and make every lookup through it walk 2^20 links.
TEST_F(ForgedHeader, Hash14ChainsCannotLoop) {
    std::uint64_t buckets = 0;
    std::memcpy(&buckets, payload.data(), 8);
    const std::uint64_t total = (payload.size() - 8) / sizeof(Hash14Entry);
    ASSERT_GT(total, buckets + 1);  // the hook's table has overflow entries
    auto link = [&](std::uint64_t from, std::uint32_t to) {
        std::memcpy(payload.data() + 8 + from * sizeof(Hash14Entry) + offsetof(Hash14Entry, next), &to, 4);
    };
    link(total - 1, static_cast<std::uint32_t>(total - 1));  // to itself
    expect_refused(good, "hash14: overflow chain loops");
    link(total - 1, static_cast<std::uint32_t>(buckets));  // back to the first overflow entry
    link(buckets, static_cast<std::uint32_t>(total - 1));  // and forward again
    expect_refused(good, "hash14: overflow chain loops");
}

TEST_F(ForgedHeader, MetadataMustDescribeThePrimitive) {
    for (const char* meta : {R"({"primitive": 7, "definition": {}})", R"([1, 2])", "{", R"({"primitive": "x"})"}) {
        TableHeader h = good;
        h.metadata = meta;
        write_table_file(path, h, payload);
        std::string e = "(no error)";
        try {
            primitive_from_metadata(read_table_header(path), path);
        } catch (const InputError& err) {
            e = err.what();
        }
        EXPECT_NE(e.find(path + ": the table's metadata"), std::string::npos) << meta << ": " << e;
    }
}

// The primitive the metadata describes must lie in the table's box, as a scene's must
// (check_inside_box): certifying a table rasterizes it, and a grid point inside its solid has no
// surface to answer with (the fuzzer's find: a hook moved half out of its box).
TEST_F(ForgedHeader, MetadataPrimitiveMustLieInTheBox) {
    const auto load = [&](const std::string& first_sphere) {
        TableHeader h = good;
        h.metadata = R"({"primitive": "hook", "definition": {"spheres": [)" + first_sphere +
                     R"(, [1, 1, 3, 0.5], [3, 1, 3, 0.5], [3, 1, 2, 0.5]],
                       "cylinders": [[0, 1, 0.5], [1, 2, 0.5], [2, 3, 0.5]]}})";
        write_table_file(path, h, payload);
        try {
            primitive_from_metadata(read_table_header(path), path);
        } catch (const InputError& err) {
            return std::string(err.what());
        }
        return std::string("(no error)");
    };
    EXPECT_EQ(load("[1, 1, 1, 0.5]"), "(no error)");
    const std::string e = load("[0, 1, 1, 0.5]");
    EXPECT_NE(e.find(path + " (metadata): primitive 'hook' reaches outside its lattice box"),
              std::string::npos)
        << e;
}

// A killed table build leaves its temporary behind; the next run that opens the cache removes
// it once it is old enough that no live writer can own it, and leaves fresh ones alone.
TEST(TableCacheTest, StaleTemporariesAreRemoved) {
    test::TempDir dir;
    const auto old_one = dir.path() / "hair-s1-hash14-0123456789abcdef.lht.tmp-AbC123";
    const auto fresh = dir.path() / "hair-s1-dense-0123456789abcdef.lht.tmp-XyZ789";
    const auto other = dir.path() / "notes.tmp-old";
    for (const auto& p : {old_one, fresh, other}) std::ofstream(p) << "partial";
    const auto long_ago = std::filesystem::file_time_type::clock::now() - std::chrono::hours(2);
    std::filesystem::last_write_time(old_one, long_ago);
    std::filesystem::last_write_time(other, long_ago);
    const TableCache cache(dir.path().string());
    EXPECT_FALSE(std::filesystem::exists(old_one));
    EXPECT_TRUE(std::filesystem::exists(fresh));
    EXPECT_TRUE(std::filesystem::exists(other));  // not ours
}

// A coverage build creates its temporary, then computes for minutes without writing to it: a
// second run opening the cache meanwhile must leave it alone, however old it looks, while its
// writer lives (it holds the temporary's lock), and remove it once the writer is gone.
TEST(TableCacheTest, ALiveWritersTemporaryIsKeptHoweverOld) {
    test::TempDir dir;
    const std::string target = (dir.path() / "ball-s4-coverage-0123456789abcdef.lht").string();
    const auto long_ago = std::filesystem::file_time_type::clock::now() - std::chrono::hours(2);
    std::string temp;
    {
        AtomicFile writing(target, "lattice table");
        temp = writing.temp_path();
        std::filesystem::last_write_time(temp, long_ago);
        const TableCache cache(dir.path().string());
        EXPECT_TRUE(std::filesystem::exists(temp));
        writing.write("table", 5);
        writing.commit();
    }
    EXPECT_TRUE(std::filesystem::exists(target));
    // A writer that died without cleaning up: its temporary holds no lock.
    const auto orphan = dir.path() / "ball-s4-coverage-0123456789abcdef.lht.tmp-Orphan";
    std::ofstream(orphan) << "partial";
    std::filesystem::last_write_time(orphan, long_ago);
    const TableCache cache(dir.path().string());
    EXPECT_FALSE(std::filesystem::exists(orphan));
}

}  // namespace
}  // namespace lat
