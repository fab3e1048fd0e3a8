// Streamed payloads (Encoding::stream, encode_payload, the table file's sink) are byte for byte
// what the encodings' whole builds give, every byte written once, and the file they make loads.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <numeric>
#include <vector>

#include "lattice/encoding.h"
#include "lattice/encodings/hash14/hash14_table.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "test_paths.h"
#include "util/hash.h"

namespace lat {
namespace {

struct Rasterized {
    TableContext ctx;
    RasterizeResult raster;
};

// The Plate 3 hair's lattice refined k times, rasterized.
const Rasterized& hair(int k) {
    static const Scene scene = load_scene(test::source_path("examples/plate3-hair-closeup.json"));
    static std::map<int, Rasterized> done;
    auto [it, fresh] = done.try_emplace(k);
    if (fresh) {
        const Primitive& p = scene.primitives.at(0);
        const LatticeSpec& l = *p.lattice;
        it->second.ctx = {
            {l.cells[0] * k, l.cells[1] * k, l.cells[2] * k}, l.sigma / k, l.sigma, p.shape.get()};
        it->second.raster = rasterize(it->second.ctx);
    }
    return it->second;
}

// A sink that records how often each byte is written, and the bytes.
class CountingSink final : public PayloadSink {
public:
    void reserve(std::size_t size) override {
        ++reserves;
        bytes.assign(size, 0);
        writes.assign(size, 0);
    }
    void write_at(std::size_t offset, const void* data, std::size_t n) override {
        ASSERT_LE(offset + n, bytes.size());
        std::memcpy(bytes.data() + offset, data, n);
        for (std::size_t i = 0; i < n; ++i) ++writes[offset + i];
    }
    int reserves = 0;
    std::vector<std::uint8_t> bytes;
    std::vector<int> writes;
};

// hash14's layout computed the plain way (docs/lattice-tables.md): N/2 buckets, hits taken
// stably by partitions of 4,096 buckets; a bucket's first hit is its head, later ones take the
// next overflow slot and go right after the head in its chain.
std::vector<std::uint8_t> hash14_reference(const RawHits& hits) {
    const std::uint64_t n = hits.size(), buckets = std::max<std::uint64_t>(1, n / 2);
    const auto bucket_of = [&](const RawHit& h) {
        return ((mix64(std::uint64_t{h.a} << 16 | h.b) >> 32) * buckets) >> 32;
    };
    const std::vector<RawHit> all = hits.flatten();
    std::vector<std::size_t> order(all.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
        return bucket_of(all[x]) >> 12 < bucket_of(all[y]) >> 12;
    });
    std::vector<Hash14Entry> e(buckets, Hash14Entry{0xFFFF, 0xFFFF, 0, 0, 0, Hash14Table::kEnd});
    for (const std::size_t i : order) {
        const RawHit& h = all[i];
        const auto t =
            static_cast<std::uint16_t>(std::lround(std::clamp(double(h.t), 0.0, 1.0) * 65535));
        const Hash14Entry entry{static_cast<std::uint16_t>(h.a),
                                static_cast<std::uint16_t>(h.b),
                                t,
                                h.nu,
                                h.nv,
                                Hash14Table::kEnd};
        Hash14Entry& head = e[bucket_of(h)];
        if (head.a == 0xFFFF) {
            head = entry;
            continue;
        }
        e.push_back(entry);
        Hash14Entry& head_again = e[bucket_of(h)];  // push_back may have moved it
        e.back().next = head_again.next;
        head_again.next = static_cast<std::uint32_t>(e.size() - 1);
    }
    std::vector<std::uint8_t> out(8 + e.size() * sizeof(Hash14Entry));
    std::memcpy(out.data(), &buckets, 8);
    std::memcpy(out.data() + 8, e.data(), e.size() * sizeof(Hash14Entry));
    return out;
}

std::vector<std::uint8_t> whole_build(const Encoding& e, const Rasterized& r) {
    const ByteBuffer b = e.build(r.raster.raw, r.ctx, {});
    return {b.data(), b.data() + b.size()};
}

// hash14 streams; dense goes through its whole build: both must give the same bytes, on
// lattices of two sizes (one group of bucket partitions, and ten).
TEST(PayloadStream, SameBytesAsTheWholeBuildEveryByteOnce) {
    for (const char* name : {"hash14", "dense"})
        for (const int k : {1, 2}) {
            SCOPED_TRACE(std::string(name) + " at sigma^-1 = " + std::to_string(k));
            const Encoding& e = find_encoding(name);
            const Rasterized& r = hair(k);
            CountingSink sink;
            encode_payload(e, RawHits(r.raster.raw), r.ctx, {}, sink);
            EXPECT_EQ(sink.reserves, 1);
            EXPECT_EQ(sink.bytes, whole_build(e, r));
            if (e.name == "hash14") {
                EXPECT_TRUE(sink.bytes == hash14_reference(r.raster.raw));
            }
            for (std::size_t i = 0; i < sink.writes.size(); ++i)
                ASSERT_EQ(sink.writes[i], 1) << "byte " << i;
        }
}

// Hits that nothing else holds are made into entries in place, in their own buffers.
TEST(PayloadStream, HitsHeldByTheEncoderAloneGiveTheSameBytes) {
    const Encoding& e = find_encoding("hash14");
    const Rasterized& r = hair(2);
    RasterizeResult own = rasterize(r.ctx);
    for (const auto& buffer : own.raw.storage) EXPECT_EQ(buffer.use_count(), 1);
    CountingSink sink;
    encode_payload(e, std::move(own.raw), r.ctx, {}, sink);
    EXPECT_TRUE(sink.bytes == whole_build(e, r));
}

// Hits rasterized as PointHits are the raw hits in hash14's stored form, in the same order;
// hash14 makes the same payload from them (the buffers its own, freed as it reads them), on
// one thread or two.
TEST(PayloadStream, PointHitsGiveTheSameBytes) {
    for (const int k : {1, 2})
        for (const int threads : {1, 2}) {
            SCOPED_TRACE("sigma^-1 = " + std::to_string(k) + ", threads " + std::to_string(threads));
            tbb::task_arena arena(threads);
            const Rasterized& r = hair(k);
            RasterizeOptions opt;
            opt.point_hits = true;
            RasterizeResult own;
            arena.execute([&] { own = rasterize(r.ctx, opt); });
            EXPECT_EQ(own.raw.size(), 0u);
            const std::vector<PointHit> points = own.points.flatten();
            const std::vector<RawHit> raw = r.raster.raw.flatten();
            ASSERT_EQ(points.size(), raw.size());
            for (std::size_t i = 0; i < raw.size(); ++i) {
                const PointHit& p = points[i];
                const RawHit& h = raw[i];
                ASSERT_TRUE(p.a == h.a && p.b == h.b && p.nu == h.nu && p.nv == h.nv) << "hit " << i;
                ASSERT_EQ(p.t, std::lround(std::clamp(double(h.t), 0.0, 1.0) * 65535)) << "hit " << i;
            }
            for (const auto& buffer : own.points.storage) EXPECT_EQ(buffer.use_count(), 1);
            CountingSink sink;
            arena.execute([&] {
                find_encoding("hash14").stream_points(std::move(own.points), r.ctx, {}, sink);
            });
            EXPECT_EQ(sink.reserves, 1);
            EXPECT_TRUE(sink.bytes == hash14_reference(r.raster.raw));
            for (std::size_t i = 0; i < sink.writes.size(); ++i)
                ASSERT_EQ(sink.writes[i], 1) << "byte " << i;
        }
}

// PointHits that something else holds too are sorted in a copy: the same payload, and the
// holder's hits are left as they were.
TEST(PayloadStream, SharedPointHitsGiveTheSameBytesAndStayUntouched) {
    const Rasterized& r = hair(1);
    RasterizeOptions opt;
    opt.point_hits = true;
    const RasterizeResult own = rasterize(r.ctx, opt);
    const std::vector<PointHit> before = own.points.flatten();
    PointHits shared = own.points;
    CountingSink sink;
    find_encoding("hash14").stream_points(std::move(shared), r.ctx, {}, sink);
    EXPECT_TRUE(sink.bytes == hash14_reference(r.raster.raw));
    const std::vector<PointHit> after = own.points.flatten();
    ASSERT_EQ(after.size(), before.size());
    EXPECT_EQ(std::memcmp(after.data(), before.data(), before.size() * sizeof(PointHit)), 0);
}

// A hash14 table's header for the hair rasterized at sigma^-1 = k.
TableHeader hash14_header(const Rasterized& r, int k) {
    TableHeader h;
    h.encoding = "hash14";
    h.cells = r.ctx.cells;
    h.sigma_inv = k;
    h.sigma = r.ctx.sigma;
    h.cell = r.ctx.cell;
    h.pairs = r.raster.pairs_eq2;
    h.entries = r.raster.hits;
    return h;
}

// The file's checksum (hashed as pieces arrive in order, the rest read back) is the whole
// payload's whatever order and size the pieces come in: in order, backwards, a little ahead of
// the bytes before them, rewriting bytes already hashed or a piece still waiting.
TEST(PayloadStream, TableFileChecksumHoldsForPiecesInAnyOrder) {
    const test::TempDir dir;
    const Rasterized& r = hair(1);
    const ByteBuffer payload = find_encoding("hash14").build(r.raster.raw, r.ctx, {});
    TableHeader h = hash14_header(r, 1);
    const std::string whole = dir.file("whole.lht");
    write_table_file(whole, h, payload);
    const std::size_t n = payload.size(), piece = 4099;  // not a multiple of 32
    const auto put = [&](PayloadSink& sink, std::size_t from, std::size_t to) {
        sink.write_at(from, payload.data() + from, to - from);
    };
    using Fill = std::function<void(PayloadSink&)>;
    const std::vector<std::pair<const char*, Fill>> orders = {
        {"in order", [&](PayloadSink& s) { for (std::size_t o = 0; o < n; o += piece) put(s, o, std::min(n, o + piece)); }},
        {"backwards", [&](PayloadSink& s) {
             for (std::size_t o = (n - 1) / piece * piece;; o -= piece) {
                 put(s, o, std::min(n, o + piece));
                 if (o == 0) break;
             }
         }},
        {"pairs swapped", [&](PayloadSink& s) {
             for (std::size_t o = 0; o < n; o += 2 * piece) {
                 if (o + piece < n) put(s, o + piece, std::min(n, o + 2 * piece));
                 put(s, o, std::min(n, o + piece));
             }
         }},
        {"hashed bytes rewritten", [&](PayloadSink& s) {
             const std::vector<std::uint8_t> junk(5000, 0xAB);
             s.write_at(0, junk.data(), junk.size());
             put(s, 0, n);
         }},
        {"waiting piece rewritten", [&](PayloadSink& s) {
             const std::vector<std::uint8_t> junk(300, 0xCD);
             s.write_at(1000, junk.data(), junk.size());
             put(s, 1000, 1300);
             put(s, 0, 1000);
             put(s, 1300, n);
         }},
    };
    for (const auto& [what, fill] : orders) {
        const std::string path = dir.file("pieces.lht");
        write_table_file(path, h, [&](PayloadSink& sink) {
            sink.reserve(n);
            fill(sink);
        });
        EXPECT_TRUE(test::slurp(path) == test::slurp(whole)) << what;
        EXPECT_NO_THROW(load_table_file(path)) << what;
    }
}

TEST(PayloadStream, NoHitsMakeTheSamePayload) {
    const Encoding& e = find_encoding("hash14");
    const Rasterized& r = hair(1);
    CountingSink sink;
    encode_payload(e, RawHits{}, r.ctx, {}, sink);
    const ByteBuffer whole = e.build(RawHits{}, r.ctx, {});
    EXPECT_EQ(sink.bytes, std::vector<std::uint8_t>(whole.data(), whole.data() + whole.size()));
}

// The file written through the sink equals the one written from the whole payload, and loads
// (its checksum, read back from the file, is right).
TEST(PayloadStream, StreamedTableFileEqualsTheWholeOne) {
    const test::TempDir dir;
    const Rasterized& r = hair(2);
    const Encoding& e = find_encoding("hash14");
    TableHeader h = hash14_header(r, 2);
    h.metadata = R"({"primitive": "hair"})";
    const std::string whole = dir.file("whole.lht"), streamed = dir.file("streamed.lht");
    write_table_file(whole, h, e.build(r.raster.raw, r.ctx, {}));
    const std::uint64_t size = write_table_file(streamed, h, [&](PayloadSink& sink) {
        encode_payload(e, RawHits(r.raster.raw), r.ctx, {}, sink);
    });
    EXPECT_EQ(size + kTableHeaderBytes + h.metadata.size(), std::filesystem::file_size(streamed));
    EXPECT_TRUE(test::slurp(whole) == test::slurp(streamed));
    const LoadedTable t = load_table_file(streamed);
    EXPECT_EQ(t.table->entries(), r.raster.hits);
    TableHit hit;
    const RawHit& first = r.raster.raw.chunks.front().front();
    EXPECT_TRUE(t.table->lookup(first.a, first.b, hit));
}

}  // namespace
}  // namespace lat
