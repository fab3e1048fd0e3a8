// Every registered encoding, through its descriptor only: a new encoding gets these tests by
// being listed in lattice/encodings/registry.cpp.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>

#include "geometry/chain.h"
#include "hook_primitive.h"
#include "lattice/boundary_grid.h"
#include "lattice/certify.h"
#include "lattice/encoding.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

using test::hook;
const TableContext& kContext = test::kHookContext;

struct Built {
    RasterizeResult raster;
    ByteBuffer payload;
    std::unique_ptr<LatticeTable> table;
};

Built build(const Encoding& e) {
    Built b;
    RasterizeOptions opt;
    opt.keep_hits = e.needs_hits;
    b.raster = rasterize(kContext, opt);
    b.payload = e.build(b.raster.raw, kContext, {});
    b.table = e.open(b.payload.data(), b.payload.size(), b.raster.hits, kContext);
    return b;
}

TableHeader header_for(const Encoding& e, const Built& b) {
    TableHeader h;
    h.encoding = e.name;
    h.cells = kContext.cells;
    h.sigma_inv = 2;
    h.sigma = kContext.sigma;
    h.cell = kContext.cell;
    h.fingerprint = 42;
    h.pairs = b.raster.pairs_eq2;
    h.entries = b.raster.hits;
    h.metadata = "{}";
    return h;
}

std::string load_error(const std::string& path) {
    try {
        load_table_file(path, nullptr, &hook());
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

// The table's answer for a pair, whichever its kind: a hit, or the candidate parts.
bool answer(const LatticeTable& t, std::uint32_t a, std::uint32_t b, TableHit& hit,
            CandidateList& list) {
    return t.kind() == LatticeTable::Kind::kCandidates ? t.candidates(a, b, list)
                                                       : t.lookup(a, b, hit);
}

class EveryEncoding : public ::testing::TestWithParam<const Encoding*> {};

TEST_P(EveryEncoding, IsFoundByItsNameOnly) {
    const Encoding& e = *GetParam();
    EXPECT_EQ(&find_encoding(e.name), &e);
    std::set<std::string_view> names;
    for (const Encoding* x : encodings()) names.insert(x->name);
    EXPECT_EQ(names.size(), encodings().size()) << "two encodings share a name";
    EXPECT_TRUE(e.build && e.open && e.error_bound);
}

TEST_P(EveryEncoding, CertifiedWithinItsDeclaredBound) {
    const Encoding& e = *GetParam();
    const Built b = build(e);
    EXPECT_EQ(b.table->kind(), e.kind);
    const CertifyReport r = certify_table(*b.table, kContext, false);
    EXPECT_GT(r.exact_hits, 1000u);
    EXPECT_EQ(r.false_misses, 0u);
    const double bound = e.error_bound(kContext, {});
    // certify reports in units of sigma, the bound is in primitive units; certify's exact hits
    // keep t as a float (relative 6e-8 of a segment no longer than the box's diagonal, 6).
    EXPECT_LE(r.max_point_error * kContext.sigma, bound * (1 + 1e-9) + 1e-6);
    if (std::isfinite(bound)) {
        EXPECT_EQ(r.false_hits, 0u);  // every answer lies near the surface
    }
    EXPECT_LE(r.max_normal_error_deg, EncodeOptions{}.max_normal_error_deg);
}

TEST_P(EveryEncoding, SameBytesForAnyThreadCount) {
    const Encoding& e = *GetParam();
    const Built two = build(e);
    Built one;
    tbb::task_arena(1).execute([&] { one = build(e); });
    ASSERT_EQ(one.payload.size(), two.payload.size());
    EXPECT_EQ(std::memcmp(one.payload.data(), two.payload.data(), one.payload.size()), 0);
}

// Shadow rays ask for t alone (LatticeTable::lookup_t): the same pairs and the same t.
TEST_P(EveryEncoding, TAloneAnswersAsTheFullLookup) {
    const Encoding& e = *GetParam();
    if (e.kind != LatticeTable::Kind::kHits) GTEST_SKIP() << "candidate tables store no t";
    const Built b = build(e);
    const BoundaryGrid grid(kContext.cells);
    int answered = 0;
    for (std::uint32_t a = 0; a < grid.count(); a += 2)
        for (std::uint32_t c = 0; c < grid.count(); c += 3) {
            TableHit hit;
            double t = -1;
            const bool full = b.table->lookup(a, c, hit);
            ASSERT_EQ(b.table->lookup_t(a, c, t), full) << a << " " << c;
            if (full) {
                EXPECT_EQ(t, hit.t) << a << " " << c;
            }
            answered += full ? 1 : 0;
        }
    EXPECT_GT(answered, 100);
}

TEST_P(EveryEncoding, RoundTripsThroughATableFile) {
    const Encoding& e = *GetParam();
    const Built b = build(e);
    test::TempDir dir;
    const std::string path = (dir.path() / "t.lht").string();
    write_table_file(path, header_for(e, b), b.payload);
    const LoadedTable t = load_table_file(path, nullptr, &hook());
    EXPECT_EQ(t.header.encoding, e.name);
    EXPECT_EQ(t.table->entries(), b.table->entries());
    const BoundaryGrid grid(kContext.cells);
    int answered = 0;
    for (std::uint32_t a = 0; a < grid.count(); a += 3)
        for (std::uint32_t c = 0; c < grid.count(); c += 5) {
            TableHit x, y;
            CandidateList cx, cy;
            const bool hx = answer(*b.table, a, c, x, cx), hy = answer(*t.table, a, c, y, cy);
            ASSERT_EQ(hx, hy) << a << " " << c;
            EXPECT_EQ(x.t, y.t);
            EXPECT_EQ(x.normal, y.normal);
            EXPECT_EQ(cx.count, cy.count);
            answered += hx ? 1 : 0;
        }
    EXPECT_GT(answered, 10);
}

TEST_P(EveryEncoding, CorruptAndTruncatedFilesAreInputErrors) {
    const Encoding& e = *GetParam();
    const Built b = build(e);
    test::TempDir dir;
    const std::string path = (dir.path() / "t.lht").string();
    // A byte changed on disk: the checksum catches it.
    write_table_file(path, header_for(e, b), b.payload);
    {
        std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(kTableHeaderBytes + b.payload.size() / 2));
        f.put('\x5a');
    }
    EXPECT_NE(load_error(path).find("checksum mismatch"), std::string::npos) << load_error(path);
    // Payloads cut short, with consistent checksums (as a forged file would have): the
    // encoding itself must refuse them.
    for (const std::size_t keep : {std::size_t{0}, std::size_t{7}, b.payload.size() / 2,
                                   b.payload.size() - 8}) {
        ByteBuffer cut(keep);
        if (keep) std::memcpy(cut.data(), b.payload.data(), keep);
        write_table_file(path, header_for(e, b), cut);
        EXPECT_NE(load_error(path).find("not a valid lattice table"), std::string::npos)
            << "kept " << keep << " of " << b.payload.size() << ": " << load_error(path);
    }
}

// A forged file (checksums recomputed) with one payload byte changed, at many places: it must
// be refused as an input error, or open into a table whose every answer stays in bounds (a
// crash or a sanitizer report here is a table trusting its file).
TEST_P(EveryEncoding, ForgedPayloadsAreRefusedOrSafe) {
    const Encoding& e = *GetParam();
    const Built b = build(e);
    test::TempDir dir;
    const std::string path = (dir.path() / "t.lht").string();
    const BoundaryGrid grid(kContext.cells);
    const std::size_t stride = std::max<std::size_t>(1, b.payload.size() / 400);
    int refused = 0, opened = 0;
    for (std::size_t at = 0; at < b.payload.size(); at += at < 128 ? 1 : stride) {
        for (const std::uint8_t flip : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
            ByteBuffer forged(b.payload.size());
            std::memcpy(forged.data(), b.payload.data(), b.payload.size());
            forged.data()[at] ^= flip;
            write_table_file(path, header_for(e, b), forged);
            LoadedTable t;
            try {
                t = load_table_file(path, nullptr, &hook());
            } catch (const InputError&) {
                ++refused;
                continue;
            }
            ++opened;
            for (std::uint32_t x = 0; x < grid.count(); x += 7)
                for (std::uint32_t y = 0; y < grid.count(); y += 11) {
                    TableHit hit;
                    CandidateList list;
                    if (!answer(*t.table, x, y, hit, list)) continue;
                    ASSERT_LE(static_cast<std::size_t>(list.count), hook().part_count());
                    for (int k = 0; k < list.count; ++k)
                        ASSERT_LT(list.parts[k], hook().part_count());
                    ASSERT_TRUE(std::isfinite(hit.t) && std::isfinite(hit.normal.x)) << at;
                }
        }
    }
    EXPECT_GT(refused + opened, 100);
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryEncoding, ::testing::ValuesIn(encodings().begin(), encodings().end()),
                         [](const ::testing::TestParamInfo<const Encoding*>& p) {
                             return std::string(p.param->name);
                         });

}  // namespace
}  // namespace lat
