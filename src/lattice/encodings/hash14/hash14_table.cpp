#include "lattice/encodings/hash14/hash14_table.h"

#include <tbb/parallel_for.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "lattice/encoding.h"
#include "lattice/octahedral.h"
#include "util/hash.h"

namespace lat {
namespace {

// Payload: u64 bucket count, then the entries (buckets first, then overflow).
constexpr std::size_t kHeader = 8;

// Multiply-shift range reduction (Lemire) of a mixed key; buckets < 2^32.
std::uint64_t bucket_of(std::uint32_t a, std::uint32_t b, std::uint64_t buckets) {
    const std::uint64_t h = mix64((static_cast<std::uint64_t>(a) << 16) | b);
    return ((h >> 32) * buckets) >> 32;
}

// A hit as its finished entry, without its link (the form the rasterizer can keep hits in). Its
// bucket is hashed again where it is needed rather than kept: at 10 bytes, entries are sorted
// in the place the hits were, and a raw hit's compaction frees the other half.
using Sorted = PointHit;

// The indices of hits.chunks that lie in each buffer of hits.storage, in address order.
template <class Hit>
std::vector<std::vector<std::size_t>> chunks_by_buffer(const HitChunks<Hit>& hits) {
    const std::size_t nbuf = hits.storage.size();
    std::vector<std::vector<std::size_t>> in_buffer(nbuf);
    const auto holds = [&](std::size_t j, const std::uint8_t* p) {
        return p >= hits.storage[j]->data() &&
               p < hits.storage[j]->data() + hits.storage[j]->size();
    };
    for (std::size_t c = 0; c < hits.chunks.size(); ++c) {
        if (hits.chunks[c].empty()) continue;
        const auto* p = reinterpret_cast<const std::uint8_t*>(hits.chunks[c].data());
        std::size_t j = 0;
        while (j < nbuf && !holds(j, p)) ++j;
        assert(j < nbuf && "every chunk lies in one of the hits' buffers");
        in_buffer[j].push_back(c);
    }
    for (std::vector<std::size_t>& cs : in_buffer)
        std::sort(cs.begin(), cs.end(), [&](std::size_t x, std::size_t y) {
            return hits.chunks[x].data() < hits.chunks[y].data();
        });
    return in_buffer;
}

// Every chunk of hits made into entries by to_entry(hit), in place in its buffer where
// the hits are held by nothing else: the 10 bytes a hit saves then go back to the system before
// the sorted copy is made, which reuses them. Else into a new buffer.
template <class ToEntry>
PointHits compact_hits(RawHits&& hits, ToEntry&& to_entry) {
    // Compacted in address order, an entry never overwrites a hit not yet read.
    const std::vector<std::vector<std::size_t>> in_buffer = chunks_by_buffer(hits);
    const std::size_t nbuf = hits.storage.size();
    PointHits out;
    out.chunks.resize(hits.chunks.size());
    std::vector<std::shared_ptr<const ByteBuffer>> fresh(nbuf);
    tbb::parallel_for(std::size_t{0}, nbuf, [&](std::size_t j) {
        const std::vector<std::size_t>& cs = in_buffer[j];
        std::size_t total = 0;
        for (const std::size_t c : cs) total += hits.chunks[c].size();
        // RawHits' buffers are never const objects (table.h).
        const bool ours = hits.storage[j].use_count() == 1;
        ByteBuffer* target = const_cast<ByteBuffer*>(hits.storage[j].get());
        if (!ours) {
            auto buf = std::make_shared<ByteBuffer>(total * sizeof(Sorted));
            target = buf.get();
            fresh[j] = std::move(buf);
        }
        std::uint8_t* w = target->data();
        for (const std::size_t c : cs) {
            auto* first = reinterpret_cast<const Sorted*>(w);
            for (const RawHit& in : hits.chunks[c]) {
                RawHit h;
                std::memcpy(&h, &in, sizeof h);  // read whole before its bytes are overwritten
                const Sorted e = to_entry(h);
                std::memcpy(w, &e, sizeof e);
                w += sizeof e;
            }
            out.chunks[c] = {first, hits.chunks[c].size()};
        }
        if (ours) target->shrink(total * sizeof(Sorted));
    });
    for (std::size_t j = 0; j < nbuf; ++j)
        out.storage.push_back(fresh[j] ? std::move(fresh[j]) : std::move(hits.storage[j]));
    hits = {};
    return out;
}

// Buckets are split into partitions small enough (4k buckets, 57 kB) to stay in cache while
// their entries are placed; partitions are placed in groups (16: about 1.3 MB of entries and
// 2 MB of payload, near what a core's cache holds), each group's payload written as one piece of
// buckets and one of overflow entries.
constexpr int kPartBits = 12;
constexpr std::uint64_t kLocal = (1u << kPartBits) - 1;
constexpr std::uint64_t kGroup = 16;  // partitions

struct Partitioning {
    std::uint64_t buckets, parts, groups;
    explicit Partitioning(std::uint64_t n)
        : buckets(std::max<std::uint64_t>(1, n / 2)),
          parts((buckets + kLocal) >> kPartBits),
          groups((parts + kGroup - 1) / kGroup) {
        if (buckets + n >= Hash14Table::kEnd)
            throw std::length_error("hash14: too many entries for 32-bit links");
    }
    std::uint64_t bucket(const Sorted& e) const { return bucket_of(e.a, e.b, buckets); }
    // Partition p owns buckets [b0(p), b0(p + 1)); group g partitions [p0(g), p0(g + 1)).
    std::uint64_t b0(std::uint64_t p) const { return std::min(buckets, p << kPartBits); }
    std::uint64_t p0(std::uint64_t g) const { return std::min(parts, g * kGroup); }
};

// Where the entries are once each chunk is sorted by group in place: chunk c's entries of
// group g at [local[c (groups + 1) + g], local[c (groups + 1) + g + 1]) of the chunk. The
// placement needs too where each partition's entries start in entry order (part_start, parts
// + 1 values) and its overflow entries in the payload (over_start).
struct Layout {
    std::vector<std::uint32_t> local;  // a chunk holds fewer than 2^32 entries (32-bit links)
    std::vector<std::uint64_t> part_start, over_start;
};

// Chunks as writable spans: the encoder's own where it holds the only reference to their
// buffers, else a copy of them.
std::vector<std::span<Sorted>> writable_chunks(PointHits& entries) {
    bool ours = true;
    for (const auto& b : entries.storage) ours = ours && b.use_count() == 1;
    if (!ours) {
        auto copy = std::make_shared<ByteBuffer>(std::max<std::uint64_t>(1, entries.size()) * sizeof(Sorted));
        auto* w = reinterpret_cast<Sorted*>(copy->data());
        for (std::span<const Sorted>& c : entries.chunks) {
            std::copy(c.begin(), c.end(), w);
            c = {w, c.size()};
            w += c.size();
        }
        entries.storage = {std::move(copy)};
    }
    // The buffers are never const objects (table.h).
    std::vector<std::span<Sorted>> out;
    for (const std::span<const Sorted>& c : entries.chunks)
        out.emplace_back(const_cast<Sorted*>(c.data()), c.size());
    return out;
}

// A thread's scratch for sorting one chunk: each entry's bucket, the sorted copy with its
// buckets, the chunk's count in each partition and the buckets it uses (a bitset).
struct ChunkScratch {
    std::vector<std::uint32_t> bucket, sorted_bucket;
    std::vector<Sorted> sorted;
    std::vector<std::uint64_t> part_count, used;
};

// One chunk, while it stays in cache: its count in each partition (added to s.part_count), the
// buckets it uses, and its entries sorted stably by group, in place.
void sort_chunk(std::span<Sorted> chunk, const Partitioning& pt, std::uint32_t* local,
                ChunkScratch& s) {
    s.bucket.resize(chunk.size());
    s.sorted_bucket.resize(chunk.size());
    s.sorted.resize(chunk.size());
    std::fill(local, local + pt.groups + 1, 0u);
    constexpr int kGroupShift = kPartBits + 4;
    static_assert(kGroup == 16);
    for (std::size_t i = 0; i < chunk.size(); ++i) {
        const Sorted& e = chunk[i];
        if (e.a >= Hash14Table::kMaxPoints || e.b >= Hash14Table::kMaxPoints)
            throw std::length_error("hash14: point id over 16 bits");
        const auto b = static_cast<std::uint32_t>(pt.bucket(e));  // buckets < 2^32
        s.bucket[i] = b;
        ++s.part_count[b >> kPartBits];
        ++local[(b >> kGroupShift) + 1];
    }
    for (std::uint64_t g = 0; g < pt.groups; ++g) local[g + 1] += local[g];
    // local[g] runs to group g's end as its entries are scattered, then is moved back.
    for (std::size_t i = 0; i < chunk.size(); ++i) {
        const std::uint32_t to = local[s.bucket[i] >> kGroupShift]++;
        s.sorted[to] = chunk[i];
        s.sorted_bucket[to] = s.bucket[i];
    }
    for (std::uint64_t g = pt.groups; g > 0; --g) local[g] = local[g - 1];
    local[0] = 0;
    std::copy(s.sorted.begin(), s.sorted.end(), chunk.begin());
    // In group order the bitset is visited a small range at a time.
    for (const std::uint32_t b : s.sorted_bucket) s.used[b / 64] |= std::uint64_t{1} << (b % 64);
}

// Every chunk sorted by group in place (sort_chunk, in parallel), then the partitions' starts
// in the entries and in the payload's overflow area.
Layout sort_chunks(const std::vector<std::span<Sorted>>& chunks, const Partitioning& pt) {
    const std::size_t nchunks = chunks.size();
    const std::uint64_t parts = pt.parts, row = pt.groups + 1;
    Layout l;
    l.local.resize(nchunks * row);
    const std::size_t words = (pt.buckets + 63) / 64;
    tbb::enumerable_thread_specific<ChunkScratch> scratch;
    tbb::parallel_for(std::size_t{0}, nchunks, [&](std::size_t c) {
        ChunkScratch& s = scratch.local();
        if (s.used.empty()) s.used.assign(words, 0), s.part_count.assign(parts, 0);
        sort_chunk(chunks[c], pt, &l.local[c * row], s);
    });
    std::vector<std::uint64_t> used(words, 0);
    l.part_start.assign(parts + 1, 0);
    for (const ChunkScratch& s : scratch) {
        for (std::size_t w = 0; w < s.used.size(); ++w) used[w] |= s.used[w];
        for (std::uint64_t p = 0; p < s.part_count.size(); ++p) l.part_start[p + 1] += s.part_count[p];
    }
    // Overflow entries: a partition's entries less its used buckets (b0(p) is a multiple of 64).
    l.over_start.assign(parts + 1, pt.buckets);
    for (std::uint64_t p = 0; p < parts; ++p) {
        std::uint64_t distinct = 0;
        for (std::uint64_t w = pt.b0(p) / 64; w < (pt.b0(p + 1) + 63) / 64; ++w)
            distinct += static_cast<std::uint64_t>(__builtin_popcountll(used[w]));
        l.over_start[p + 1] = l.over_start[p] + l.part_start[p + 1] - distinct;
    }
    for (std::uint64_t p = 0; p < parts; ++p) l.part_start[p + 1] += l.part_start[p];
    return l;
}

// A thread's buffers for one group at a time: its entries by partition with their buckets,
// and its payload.
struct GroupScratch {
    ByteBuffer by_part, bucket, stage;
};

// Group g's buckets, then its overflow entries, into stage; its entries (its pieces of every
// chunk in turn: entry order) by partition first. A bucket's first entry is its head; later
// ones take the next overflow slot and go right after the head in its chain.
void place_group(std::uint64_t g, const std::vector<std::span<Sorted>>& chunks,
                 const Partitioning& pt, const Layout& l, GroupScratch& s) {
    const std::uint64_t q0 = pt.p0(g), q1 = pt.p0(g + 1), row = pt.groups + 1;
    auto* mine = reinterpret_cast<Sorted*>(s.by_part.data());
    auto* mine_bucket = reinterpret_cast<std::uint32_t*>(s.bucket.data());
    std::uint64_t next[kGroup];
    for (std::uint64_t p = q0; p < q1; ++p) next[p - q0] = l.part_start[p] - l.part_start[q0];
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        const std::uint32_t* local = &l.local[c * row + g];
        // The next chunk's piece is fetched while this one is read: pieces are a few kB, far
        // apart, and each would start with misses that the hardware prefetcher cannot foresee.
        if (c + 1 < chunks.size()) {
            const std::uint32_t* next_local = local + row;
            const auto* from = reinterpret_cast<const char*>(chunks[c + 1].data() + next_local[0]);
            const auto* to = reinterpret_cast<const char*>(chunks[c + 1].data() + next_local[1]);
            for (const char* at = from; at < to; at += 64) __builtin_prefetch(at);
        }
        for (std::uint32_t i = local[0]; i < local[1]; ++i) {
            const Sorted& h = chunks[c][i];
            const auto b = static_cast<std::uint32_t>(pt.bucket(h));  // buckets < 2^32
            const std::uint64_t to = next[(b >> kPartBits) - q0]++;
            mine[to] = h;
            mine_bucket[to] = b;
        }
    }
    auto* stage = reinterpret_cast<Hash14Entry*>(s.stage.data());
    Hash14Entry* const over_stage = stage + (pt.b0(q1) - pt.b0(q0));
    for (std::uint64_t p = q0; p < q1; ++p) {
        Hash14Entry* part_out = stage + (pt.b0(p) - pt.b0(q0));
        for (std::uint64_t k = 0; k < pt.b0(p + 1) - pt.b0(p); ++k)
            part_out[k] = {0xFFFF, 0xFFFF, 0, 0, 0, Hash14Table::kEnd};
        std::uint64_t next_over = l.over_start[p];
        for (std::uint64_t i = l.part_start[p]; i < l.part_start[p + 1]; ++i) {
            const Sorted& h = mine[i - l.part_start[q0]];
            const Hash14Entry e{h.a, h.b, h.t, h.nu, h.nv, Hash14Table::kEnd};
            Hash14Entry& head = part_out[mine_bucket[i - l.part_start[q0]] & kLocal];
            if (head.a == 0xFFFF) {
                head = e;
                continue;
            }
            Hash14Entry& slot = over_stage[next_over - l.over_start[q0]];
            slot = e;
            slot.next = head.next;
            head.next = static_cast<std::uint32_t>(next_over++);
        }
    }
}

// The payload from the entries (chunks in entry order), freeing them at the end. Groups are
// placed in parallel, each written as two contiguous ranges of the payload (its buckets, its
// overflow entries).
void place(PointHits&& entries, PayloadSink& sink) {
    const Partitioning pt(entries.size());
    const std::vector<std::span<Sorted>> chunks = writable_chunks(entries);
    const Layout l = sort_chunks(chunks, pt);
    sink.reserve(kHeader + l.over_start[pt.parts] * sizeof(Hash14Entry));
    sink.write_at(0, &pt.buckets, kHeader);
    std::uint64_t most_entries = 0, most_stage = 0;
    for (std::uint64_t g = 0; g < pt.groups; ++g) {
        const std::uint64_t q0 = pt.p0(g), q1 = pt.p0(g + 1);
        most_entries = std::max(most_entries, l.part_start[q1] - l.part_start[q0]);
        most_stage = std::max(most_stage, (pt.b0(q1) - pt.b0(q0)) + (l.over_start[q1] - l.over_start[q0]));
    }
    tbb::enumerable_thread_specific<GroupScratch> scratch;
    std::mutex writing;  // the sink takes one piece at a time
    // Groups are taken in order, so that their buckets reach the sink nearly in order (a file
    // sink hashes what comes in order as it goes by).
    std::atomic<std::uint64_t> next_group{0};
    const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
    tbb::parallel_for(0, workers, [&](int) {
        GroupScratch& s = scratch.local();
        if (!s.stage.data()) {
            s.by_part = ByteBuffer(most_entries * sizeof(Sorted), ByteBuffer::Pages::kSmall);
            s.bucket = ByteBuffer(most_entries * sizeof(std::uint32_t), ByteBuffer::Pages::kSmall);
            s.stage = ByteBuffer(most_stage * sizeof(Hash14Entry), ByteBuffer::Pages::kSmall);
        }
        for (std::uint64_t g; (g = next_group++) < pt.groups;) {
            place_group(g, chunks, pt, l, s);
            const auto* stage = reinterpret_cast<const Hash14Entry*>(s.stage.data());
            const std::uint64_t q0 = pt.p0(g), q1 = pt.p0(g + 1), nb = pt.b0(q1) - pt.b0(q0);
            const std::lock_guard<std::mutex> lock(writing);
            sink.write_at(kHeader + pt.b0(q0) * sizeof(Hash14Entry), stage, nb * sizeof(Hash14Entry));
            sink.write_at(kHeader + l.over_start[q0] * sizeof(Hash14Entry), stage + nb,
                          (l.over_start[q1] - l.over_start[q0]) * sizeof(Hash14Entry));
        }
    }, tbb::simple_partitioner());
    entries = {};
}

}  // namespace

ByteBuffer Hash14Table::build(const RawHits& hits) {
    BufferSink sink;
    write(RawHits(hits), sink);  // shares the hits' storage: frees nothing of the caller's
    return sink.take();
}

void Hash14Table::write(RawHits&& hits, PayloadSink& sink) {
    place(compact_hits(std::move(hits),
                       [&](const RawHit& h) {
                           if (h.a >= kMaxPoints || h.b >= kMaxPoints)
                               throw std::length_error("hash14: point id over 16 bits");
                           return Sorted{static_cast<std::uint16_t>(h.a),
                                         static_cast<std::uint16_t>(h.b), quantise_t16(h.t),
                                         h.nu, h.nv};
                       }),
          sink);
}

void Hash14Table::write(PointHits&& hits, PayloadSink& sink) { place(std::move(hits), sink); }

Hash14Table::Hash14Table(const std::uint8_t* payload, std::size_t size, std::uint64_t entries)
    : entries_(entries), size_(size) {
    if (size < kHeader) throw std::runtime_error("hash14: payload too small");
    std::memcpy(&buckets_, payload, 8);
    // Compared by division: a forged bucket count must not overflow the product.
    if (buckets_ == 0 || buckets_ > (size - kHeader) / sizeof(Hash14Entry) ||
        (size - kHeader) % sizeof(Hash14Entry) != 0)
        throw std::runtime_error("hash14: inconsistent payload size");
    e_ = reinterpret_cast<const Hash14Entry*>(payload + kHeader);
    const std::uint64_t total = (size - kHeader) / sizeof(Hash14Entry);
    // Every chain link must stay inside the table (a corrupt file must not crash lookups) and
    // lead into the overflow area, and an overflow entry's link back to an earlier one (the
    // build appends each entry after its bucket's head, linking it to the one there before), so
    // that no chain loops: a loop would cost every lookup through it 2^20 steps.
    for (std::uint64_t k = 0; k < total; ++k) {
        const std::uint32_t next = e_[k].next;
        if (next == kEnd) continue;
        if (next >= total || next < buckets_)
            throw std::runtime_error("hash14: overflow chain out of range");
        if (k >= buckets_ && next >= k) throw std::runtime_error("hash14: overflow chain loops");
    }
}

bool Hash14Table::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    if (a >= kMaxPoints || b >= kMaxPoints) return false;
    const Hash14Entry* e = e_ + bucket_of(a, b, buckets_);
    for (int guard = 0; guard < 1 << 20; ++guard) {
        if (e->a == a && e->b == b) {
            hit.t = e->t * (1.0 / 65535.0);
            hit.normal = oct_decode({e->nu, e->nv}, kRawNormalBits);
            return true;
        }
        if (e->next == kEnd) return false;
        e = e_ + e->next;
    }
    return false;  // a forged chain this long (open refuses loops)
}

}  // namespace lat
