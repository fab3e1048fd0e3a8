// The perfect-hash encodings (paper 5.2.1): the BBHash minimal perfect hash function, the
// 5-byte table over it, its certified false hits, and the fingerprinted variants.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "geometry/chain.h"
#include "lattice/bits/bbhash.h"
#include "lattice/boundary_grid.h"
#include "lattice/certify.h"
#include "lattice/encoding.h"
#include "lattice/octahedral.h"
#include "lattice/encodings/perfect/perfect_table.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "temp_dir.h"

namespace lat {
namespace {

// The hook of the paper's Figure 1, as in examples/table1.json.
ChainShape hook() {
    return ChainShape({{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}},
                      {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}});
}

std::vector<std::uint64_t> random_keys(std::size_t n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<std::uint64_t> keys;
    while (keys.size() < n) {
        for (std::size_t i = keys.size(); i < n; ++i)
            keys.push_back(rng() >> 1);  // top bit: not a key
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    }
    std::shuffle(keys.begin(), keys.end(), rng);
    return keys;
}

const std::uint8_t* bytes_of(const std::vector<std::uint64_t>& w) {
    return reinterpret_cast<const std::uint8_t*>(w.data());
}

template <class F>
auto with_threads(int threads, F f) {
    tbb::task_arena arena(threads);
    decltype(f()) out;
    arena.execute([&] { out = f(); });
    return out;
}

TEST(Perfect5Mphf, BijectionOntoRangeOnRandomKeySets) {
    for (const std::size_t n : {0, 1, 2, 3, 64, 1000, 300000}) {
        const std::vector<std::uint64_t> keys = random_keys(n, n + 7);
        const std::vector<std::uint64_t> words = BBHash::build(keys);
        const BBHash f(bytes_of(words), words.size() * 8);
        ASSERT_EQ(f.keys(), n);
        std::vector<bool> taken(n, false);
        for (const std::uint64_t k : keys) {
            const std::uint64_t v = f(k);
            ASSERT_LT(v, n) << "n=" << n;
            ASSERT_FALSE(taken[v]) << "n=" << n;
            taken[v] = true;
        }
        if (n >= 100000) {
            EXPECT_LT(8.0 * double(f.bytes()) / double(n), 3.8) << "bits per key";
        }
        // A key outside the set falls through every level with the predicted probability.
        std::mt19937_64 rng(n);
        const int trials = 200000;
        int rejected = 0;
        for (int i = 0; i < trials; ++i)
            rejected += f(rng() | (std::uint64_t{1} << 63)) == BBHash::kNone;
        const double p = 1 - f.accept_rate();
        EXPECT_NEAR(rejected, p * trials, 5 * std::sqrt(p * (1 - p) * trials) + 1) << "n=" << n;
        if (n == 0) {
            EXPECT_EQ(rejected, trials);
        }
    }
}

TEST(Perfect5Mphf, OtherGammasAreBijectionsToo) {
    const std::vector<std::uint64_t> keys = random_keys(50000, 3);
    for (const double gamma : {1.0, 1.5, 3.0}) {
        const std::vector<std::uint64_t> words = BBHash::build(keys, gamma);
        const BBHash f(bytes_of(words), words.size() * 8);
        std::set<std::uint64_t> values;
        for (const std::uint64_t k : keys) values.insert(f(k));
        EXPECT_EQ(values.size(), keys.size());
        EXPECT_LT(*values.rbegin(), keys.size());
    }
}

TEST(Perfect5Mphf, DependsOnTheKeySetOnly) {
    std::vector<std::uint64_t> keys = random_keys(200000, 5);
    const auto one = with_threads(1, [&] { return BBHash::build(keys); });
    const auto two = with_threads(2, [&] { return BBHash::build(keys); });
    std::reverse(keys.begin(), keys.end());
    const auto reversed = BBHash::build(keys);
    EXPECT_EQ(one, two);
    EXPECT_EQ(one, reversed);
}

TEST(Perfect5Mphf, RejectsDuplicateKeysAndCorruptWords) {
    EXPECT_THROW(BBHash::build(std::vector<std::uint64_t>{1, 2, 3, 2}), std::invalid_argument);
    const std::vector<std::uint64_t> good = BBHash::build(random_keys(5000, 9));
    auto opens = [](std::vector<std::uint64_t> w) {
        try {
            const BBHash f(bytes_of(w), w.size() * 8);
            return true;
        } catch (const std::runtime_error&) {
            return false;
        }
    };
    EXPECT_TRUE(opens(good));
    auto corrupt = [&](std::size_t word, std::uint64_t value) {
        std::vector<std::uint64_t> w = good;
        w[word] = value;
        return w;
    };
    EXPECT_FALSE(opens(corrupt(0, 5001)));             // key count
    EXPECT_FALSE(opens(corrupt(1, 65)));               // level count
    EXPECT_FALSE(opens(corrupt(2, good[2] + 1)));      // words
    EXPECT_FALSE(opens(corrupt(4, 0)));                // a level start
    EXPECT_FALSE(opens(corrupt(good.size() - 2, 0)));  // rank samples (or the bit count)
    const std::size_t bits_at = 3 + good[1] + 1;
    EXPECT_FALSE(opens(corrupt(bits_at, good[bits_at] ^ 1)));  // bit count
    std::vector<std::uint64_t> shorter = good;
    shorter.pop_back();
    EXPECT_FALSE(opens(shorter));
    EXPECT_THROW(BBHash(bytes_of(good) + 4, 32), std::runtime_error);  // misaligned
}

RasterizeResult hook_hits(int k) {
    static const ChainShape shape = hook();
    return rasterize({{4 * k, 2 * k, 4 * k}, 1.0 / k, 1.0, &shape});
}

TEST(Perfect5Table, StoredPairsComeBackWithinQuantisation) {
    const RasterizeResult r = hook_hits(2);
    const ByteBuffer payload = PerfectTable::build(r.raw, 0);
    const PerfectTable table(payload.data(), payload.size(), r.raw.size(), 0);
    EXPECT_EQ(table.encoding(), "perfect5");
    EXPECT_EQ(table.entries(), r.raw.size());
    EXPECT_EQ(table.bytes(), 24 + table.mphf().bytes() + 5 * r.raw.size());
    EXPECT_LT(double(table.bytes()) / double(r.raw.size()), 5.6);
    for (const RawHit& h : r.raw.flatten()) {
        TableHit th;
        ASSERT_TRUE(table.lookup(h.a, h.b, th));
        EXPECT_NEAR(th.t, h.t, 0.5 / 65535 + 1e-7);
        // 12 + 12-bit octahedral codes are within 0.04 degrees of the 16 + 16-bit ones.
        const Vec3 n = oct_decode({h.nu, h.nv}, kRawNormalBits);
        EXPECT_GT(dot(n, th.normal), std::cos(0.04 * M_PI / 180));
    }
}

TEST(Perfect5Table, PayloadIndependentOfThreadCount) {
    const RasterizeResult r = hook_hits(4);
    for (const int fp : {0, 16}) {
        const ByteBuffer one = with_threads(1, [&] { return PerfectTable::build(r.raw, fp); });
        const ByteBuffer two = with_threads(2, [&] { return PerfectTable::build(r.raw, fp); });
        ASSERT_EQ(one.size(), two.size());
        EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size()), 0);
    }
}

// Certified against exact intersection: no false misses; of the pairs that should miss, those
// the MPHF accepts (nearly all) are false hits, and a k-bit fingerprint keeps 2^-k of them.
TEST(Perfect5Table, CertifiedFalseHitsAreThePredictedShareOfMisses) {
    const ChainShape s = hook();
    const int k = 4;
    const RasterizeResult r = hook_hits(k);
    const TableContext ctx{{4 * k, 2 * k, 4 * k}, 1.0 / k, 1.0, &s};
    for (const int fp : {0, 8, 16}) {
        const std::string name = PerfectTable::name(fp);
        const Encoding& e = find_encoding(name);
        const ByteBuffer payload = e.build(r.raw, ctx, {});
        const auto table = e.open(payload.data(), payload.size(), r.raw.size(), ctx);
        const CertifyReport rep = certify_table(*table, ctx, false);
        const auto& perfect = dynamic_cast<const PerfectTable&>(*table);
        EXPECT_EQ(rep.false_misses, 0u) << name;
        EXPECT_EQ(rep.exact_hits, r.raw.size()) << name;
        EXPECT_LT(rep.max_point_error, 1e-3) << name;
        // The 24-bit code's 0.04 degrees on top of the rasterizer's 16 + 16-bit code.
        EXPECT_LT(rep.max_normal_error_deg, 0.06) << name;
        const double misses = double(rep.pairs - rep.exact_hits);
        const double p = perfect.mphf().accept_rate() * std::ldexp(1.0, -fp);
        const double expected = misses * p;
        EXPECT_NEAR(double(rep.false_hits), expected, 5 * std::sqrt(expected * (1 - p)) + 2)
            << name << ": " << rep.false_hits << " false hits of " << misses << " misses";
        if (fp == 0) {
            EXPECT_GT(double(rep.false_hits), 0.9 * misses);
        }
    }
}

TEST(Perfect5Table, RejectsShortOrCorruptPayloads) {
    const RasterizeResult r = hook_hits(1);
    const std::uint64_t n = r.raw.size();
    const ByteBuffer payload = PerfectTable::build(r.raw, 0);
    auto error = [&](std::size_t size, std::uint64_t entries, int fp, std::size_t poke = 0,
                     std::uint8_t value = 0) -> std::string {
        std::vector<std::uint64_t> copy((payload.size() + 7) / 8);
        std::memcpy(copy.data(), payload.data(), payload.size());
        if (poke) reinterpret_cast<std::uint8_t*>(copy.data())[poke] = value;
        try {
            const PerfectTable t(bytes_of(copy), size, entries, fp);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "(no error)";
    };
    EXPECT_EQ(error(payload.size(), n, 0), "(no error)");
    EXPECT_EQ(error(20, n, 0), "perfect: payload too small");
    EXPECT_EQ(error(payload.size() - 1, n, 0), "perfect: inconsistent payload size");
    EXPECT_EQ(error(payload.size(), n + 1, 0), "perfect: payload holds another number of hits");
    EXPECT_EQ(error(payload.size(), n, 8), "perfect: payload has another entry layout");
    EXPECT_EQ(error(payload.size(), n, 0, 17, 0xFF), "perfect: inconsistent payload size");
    EXPECT_NE(error(payload.size(), n, 0, 24 + 8, 0x7F).find("bbhash"), std::string::npos);
    // Entries hold no offsets: any bytes there are a valid (if wrong) table.
    EXPECT_EQ(error(payload.size(), n, 0, payload.size() - 3, 0xAB), "(no error)");
}

TEST(Perfect5Table, RoundTripsThroughATableFile) {
    test::TempDir dir;
    const RasterizeResult r = hook_hits(2);
    EXPECT_TRUE(find_encoding("perfect5").needs_hits);
    TableHeader h;
    h.encoding = "perfect7";
    h.cells = {8, 4, 8};
    h.sigma_inv = 2;
    h.cell = 0.5;
    h.pairs = r.pairs_eq2;
    h.entries = r.hits;
    const std::string path = dir.file("hook.lht");
    write_table_file(path, h, find_encoding("perfect7").build(r.raw, h.context(nullptr), {}));
    const LoadedTable t = load_table_file(path, &h);
    EXPECT_EQ(t.table->encoding(), "perfect7");
    EXPECT_EQ(t.table->entries(), r.raw.size());
    for (const RawHit& hit : r.raw.flatten()) {
        TableHit th;
        ASSERT_TRUE(t.table->lookup(hit.a, hit.b, th));
        EXPECT_NEAR(th.t, hit.t, 0.5 / 65535 + 1e-7);
    }
}

}  // namespace
}  // namespace lat
