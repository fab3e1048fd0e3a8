// Lattices: boundary grid ids, rasterization against brute force, the hash14 table, the table
// file format, and lattice shapes against exact intersection.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <map>

#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "geometry/chain.h"
#include "geometry/parts.h"
#include "lattice/boundary_grid.h"
#include "lattice/encoding.h"
#include "lattice/encodings/hash14/hash14_table.h"
#include "lattice/lattice_shape.h"
#include "lattice/octahedral.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "temp_dir.h"
#include "util/error.h"

namespace lat {
namespace {

// The hook of the paper's Figure 1, as in examples/table1.json.
ChainShape hook() {
    return ChainShape({{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}},
                      {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}});
}

TEST(BoundaryGridTest, IdsRoundTripAndCounts) {
    const BoundaryGrid g({4, 2, 5});
    std::set<std::uint32_t> seen;
    int boundary = 0;
    for (int z = 0; z <= 5; ++z)
        for (int y = 0; y <= 2; ++y)
            for (int x = 0; x <= 4; ++x) {
                const GridPoint p{x, y, z};
                if (g.faces(p) == 0) continue;
                ++boundary;
                const std::uint32_t id = g.id(p);
                EXPECT_LT(id, g.count());
                EXPECT_TRUE(seen.insert(id).second);
                EXPECT_EQ(g.point(id), p);
            }
    EXPECT_EQ(static_cast<std::uint32_t>(boundary), g.count());
    EXPECT_EQ(g.faces({0, 0, 0}), 0b010101);
    EXPECT_EQ(g.faces({4, 1, 5}), 0b100010);
}

TEST(BoundaryGridTest, PaperFigure1PairCount) {
    // Paper 2.2: a 4 x 2 x 4 lattice has N_lpxy = 15, N_lpyz = 15, N_lpzx = 25, N_lp = 9,950.
    const BoundaryGrid g({4, 2, 4});
    EXPECT_EQ(g.face_points(4), 15u);
    EXPECT_EQ(g.face_points(0), 15u);
    EXPECT_EQ(g.face_points(2), 25u);
    EXPECT_EQ(g.pairs_eq2(), 9950u);
}

// Every valid pair traced exactly against every part, the slow way.
std::map<std::pair<std::uint32_t, std::uint32_t>, double> brute_force(const Shape& s, const TableContext& lg) {
    const BoundaryGrid g(lg.cells);
    std::map<std::pair<std::uint32_t, std::uint32_t>, double> hits;
    for (std::uint32_t a = 0; a < g.count(); ++a)
        for (std::uint32_t b = 0; b < g.count(); ++b) {
            const GridPoint pa = g.point(a), pb = g.point(b);
            if (a == b || !BoundaryGrid::valid_pair(g.faces(pa), g.faces(pb))) continue;
            const Vec3 p{double(pa.x), double(pa.y), double(pa.z)}, q{double(pb.x), double(pb.y), double(pb.z)};
            Crossing c;
            double best = kInfinity;
            for (std::size_t i = 0; i < ShapeParts(s).part_count(); ++i)
                if (ShapeParts(s).intersect_part(i, {p * lg.cell, (q - p) * lg.cell}, 0.0, 1.0 + 1e-12, c))
                    best = std::min(best, c.t);
            if (best <= 1.0) hits[{a, b}] = best;
        }
    return hits;
}

TEST(LatticeRasterize, MatchesBruteForceOnTheHook) {
    const ChainShape s = hook();
    for (int k : {1, 2}) {
        const TableContext lg{{4 * k, 2 * k, 4 * k}, 1.0 / k, 1.0, &s};
        const RasterizeResult r = rasterize(lg);
        const auto expected = brute_force(s, lg);
        ASSERT_EQ(r.raw.size(), expected.size()) << "k=" << k;
        EXPECT_EQ(r.pairs_eq2, r.pairs_enumerated);
        for (const RawHit& h : r.raw.flatten()) {
            auto it = expected.find({h.a, h.b});
            ASSERT_NE(it, expected.end());
            EXPECT_NEAR(h.t, it->second, 1e-6);
        }
    }
}

TEST(LatticeRasterize, MatchesBruteForceOnARandomChain) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.6, 5.4), rr(0.2, 0.55);
    std::vector<ChainSphere> spheres;
    std::vector<ChainCylinder> cyl;
    for (int i = 0; i < 6; ++i) spheres.push_back({{u(rng), u(rng), u(rng)}, rr(rng)});
    for (int i = 0; i + 1 < 6; ++i) cyl.push_back({i, i + 1, std::min(spheres[i].radius, spheres[i + 1].radius)});
    const ChainShape s(spheres, cyl);
    const TableContext lg{{6, 6, 6}, 1.0, 1.0, &s};
    const RasterizeResult r = rasterize(lg);
    EXPECT_EQ(r.raw.size(), brute_force(s, lg).size());
    EXPECT_LT(r.tests, 4 * r.hits);  // the cone culling does its job
}

TEST(LatticeRasterize, PartsBeyondWhatAHitRecordsAreAnInputError) {
    // A hit records its part in 16 bits (a chain of at most 16,384 parts): a chain of 16,400
    // spheres, the last the largest, cannot have a hit table, and says so; counting its hits
    // (candidates tables need no parts) still works.
    std::vector<ChainSphere> spheres;
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(0.5, 3.5);
    for (int i = 0; i < 16399; ++i) spheres.push_back({{u(rng), u(rng), u(rng)}, 0.02});
    spheres.push_back({{2, 2, 2}, 1.0});
    const ChainShape chain(spheres, {});
    const TableContext ctx{{4, 4, 4}, 1.0, 1.0, &chain};
    EXPECT_THROW(rasterize(ctx), InputError);
    RasterizeOptions count_only;
    count_only.keep_hits = false;
    EXPECT_GT(rasterize(ctx, count_only).hits, 100u);
}

TEST(LatticeRasterize, IndependentOfThreadCount) {
    const ChainShape s = hook();
    const TableContext lg{{8, 4, 8}, 0.5, 1.0, &s};
    const RasterizeResult one = [&] {
        tbb::task_arena arena(1);
        RasterizeResult r;
        arena.execute([&] { r = rasterize(lg); });
        return r;
    }();
    const RasterizeResult two = rasterize(lg);
    const std::vector<RawHit> h1 = one.raw.flatten(), h2 = two.raw.flatten();
    ASSERT_EQ(h1.size(), h2.size());
    for (std::size_t i = 0; i < h1.size(); ++i) {
        EXPECT_EQ(h1[i].a, h2[i].a);
        EXPECT_EQ(h1[i].b, h2[i].b);
        EXPECT_EQ(h1[i].t, h2[i].t);
    }
}

TEST(LatticeHash14, StoredPairsComeBackWithinQuantisation) {
    const ChainShape s = hook();
    const TableContext lg{{8, 4, 8}, 0.5, 1.0, &s};
    const RasterizeResult r = rasterize(lg);
    const ByteBuffer payload = Hash14Table::build(r.raw);
    const Hash14Table table(payload.data(), payload.size(), r.raw.size());
    EXPECT_LT(double(table.bytes()) / double(r.raw.size()), 16.0);
    std::set<std::pair<std::uint32_t, std::uint32_t>> present;
    for (const RawHit& h : r.raw.flatten()) {
        present.insert({h.a, h.b});
        TableHit th;
        ASSERT_TRUE(table.lookup(h.a, h.b, th));
        EXPECT_NEAR(th.t, h.t, 0.5 / 65535 + 1e-7);
        const Vec3 n = oct_decode({h.nu, h.nv}, kRawNormalBits);
        EXPECT_GT(dot(n, th.normal), std::cos(0.01 * M_PI / 180));
    }
    // Pairs that are not stored are misses.
    const BoundaryGrid g(lg.cells);
    int misses = 0;
    for (std::uint32_t a = 0; a < g.count(); a += 3)
        for (std::uint32_t b = 0; b < g.count(); b += 5) {
            if (present.count({a, b})) continue;
            TableHit th;
            EXPECT_FALSE(table.lookup(a, b, th));
            ++misses;
        }
    EXPECT_GT(misses, 1000);
}

class LatticeFile : public ::testing::Test {
protected:
    test::TempDir dir;
    TableHeader header;
    std::string path;
    void SetUp() override {
        const ChainShape s = hook();
        const TableContext lg{{4, 2, 4}, 1.0, 1.0, &s};
        RasterizeResult r = rasterize(lg);
        header.encoding = "hash14";
        header.cells = lg.cells;
        header.cell = 1.0;
        header.fingerprint = 1234;
        header.pairs = r.pairs_eq2;
        header.entries = r.hits;
        path = (dir.path() / "hook.lht").string();
        write_table_file(path, header, find_encoding("hash14").build(r.raw, lg, {}));
    }
    std::string load_error(const TableHeader* expected = nullptr) {
        try {
            load_table_file(path, expected);
        } catch (const InputError& e) {
            return e.what();
        }
        return "(no error)";
    }
    void poke(std::size_t offset, char value) {
        std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(offset));
        f.put(value);
    }
};

TEST_F(LatticeFile, RoundTrip) {
    const LoadedTable t = load_table_file(path, &header);
    EXPECT_EQ(t.header.entries, header.entries);
    EXPECT_EQ(t.table->entries(), header.entries);
    EXPECT_EQ(t.table->encoding(), "hash14");
}

TEST_F(LatticeFile, RejectsTruncatedFile) {
    std::filesystem::resize_file(path, std::filesystem::file_size(path) - 7);
    EXPECT_NE(load_error().find("hook.lht: not a valid lattice table: file holds"), std::string::npos)
        << load_error();
    std::filesystem::resize_file(path, 40);
    EXPECT_NE(load_error().find("too short"), std::string::npos);
}

TEST_F(LatticeFile, RejectsCorruptPayloadAndHeader) {
    poke(kTableHeaderBytes + 100, 0x5a);
    EXPECT_NE(load_error().find("payload checksum mismatch"), std::string::npos) << load_error();
    poke(3, 'X');
    EXPECT_NE(load_error().find("wrong magic number"), std::string::npos);
}

TEST_F(LatticeFile, RejectsTableOfAnotherPrimitive) {
    TableHeader other = header;
    other.fingerprint = 99;
    EXPECT_NE(load_error(&other).find("built for another primitive"), std::string::npos);
    other = header;
    other.cells = {8, 4, 8};
    EXPECT_NE(load_error(&other).find("lattice table is for hash14, 4 x 2 x 4 cells"), std::string::npos)
        << load_error(&other);
}

ChainShape grown_hook(double dr) {
    const double r = 0.5 + dr;
    return ChainShape({{{1, 1, 1}, r}, {{1, 1, 3}, r}, {{3, 1, 3}, r}, {{3, 1, 2}, r}},
                      {{0, 1, r}, {1, 2, r}, {2, 3, r}});
}

TEST(LatticeShapeTest, AgreesWithExactUpToACell) {
    // A snapped segment lies within 0.71 cells of its ray, so the lattice must hit every ray
    // that meets the hook thinned by a cell, miss every ray that misses it thickened by a
    // cell, and put the first hit between the two shapes' first crossings.
    const ChainShape s = hook();
    const int k = 4;
    const double cell = 1.0 / k;
    const TableContext lg{{4 * k, 2 * k, 4 * k}, cell, 1.0, &s};
    const RasterizeResult r = rasterize(lg);
    const auto payload = find_encoding("hash14").build(r.raw, lg, {});
    auto table = std::make_shared<Hash14Table>(payload.data(), payload.size(), r.hits);
    const auto ls = make_lattice_shape(table, lg, kInfinity);
    const ChainShape thin = grown_hook(-cell), thick = grown_hook(cell);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    int hits = 0, misses = 0, normals_checked = 0, far_off = 0;
    double cos_sum = 0;
    for (int n = 0; n < 20000; ++n) {
        const Vec3 target{1 + 2 * (u(rng) + 1), 1 + 0.5 * u(rng), 1 + 2 * (u(rng) + 1)};
        const Vec3 d = normalize(Vec3{u(rng), u(rng), u(rng)});
        const Ray ray{target - d * 10, d};
        Crossing cl, c_thin, c_thick, ce;
        const bool lattice = ls->intersect(ray, 0, kInfinity, cl);
        const bool in_thin = thin.intersect(ray, 0, kInfinity, c_thin);
        const bool in_thick = thick.intersect(ray, 0, kInfinity, c_thick);
        if (in_thin) {
            ++hits;
            ASSERT_TRUE(lattice) << n;
            EXPECT_GE(cl.t, c_thick.t - 1e-9) << n;
            EXPECT_LE(cl.t, c_thin.t + 2 * cell) << n;
            // Where the lattice and the exact hit agree, so do their normals, but for hits
            // near the junctions of spheres and flat cylinder ends.
            if (s.intersect(ray, 0, kInfinity, ce) && std::abs(ce.t - cl.t) < 0.5 * cell) {
                const double c = dot(ls->normal(ray, cl), s.normal(ray, ce));
                cos_sum += c;
                far_off += c < 0.3;
                ++normals_checked;
            }
        }
        if (!in_thick) {
            ++misses;
            EXPECT_FALSE(lattice) << n;
        }
    }
    EXPECT_GT(hits, 1000);
    EXPECT_GT(misses, 1000);
    EXPECT_GT(normals_checked, 1000);
    EXPECT_GT(cos_sum / normals_checked, 0.95);
    EXPECT_LT(far_off, normals_checked / 100);
}

}  // namespace
}  // namespace lat
