#include "lattice/encodings/hash14/hash14_table.h"

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
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

// A hit as its finished entry, without its link. Its bucket is hashed again where it is needed
// rather than kept: at 10 bytes, the half of a raw hit that compaction frees holds the whole
// sorted copy.
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

// Every chunk of hits made into entries by to_entry(hit, chunk), in place in its buffer where
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
                const Sorted e = to_entry(h, c);
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
// their hits are placed; hits are first sorted stably into their partitions, as finished
// entries (10 bytes: the sorted copy is written once and read twice, and fresh memory is dear).
constexpr int kPartBits = 12;
constexpr std::uint64_t kLocal = (1u << kPartBits) - 1;

struct Partitioning {
    std::uint64_t buckets, parts;
    explicit Partitioning(std::uint64_t n)
        : buckets(std::max<std::uint64_t>(1, n / 2)), parts((buckets + kLocal) >> kPartBits) {
        if (buckets + n >= Hash14Table::kEnd)
            throw std::length_error("hash14: too many entries for 32-bit links");
    }
    std::uint64_t bucket(std::uint32_t a, std::uint32_t b) const { return bucket_of(a, b, buckets); }
    std::uint64_t part(std::uint32_t a, std::uint32_t b) const { return bucket(a, b) >> kPartBits; }
};

// The payload from the entries (chunks in entry order; count[c * parts + p]: chunk c's entries
// in partition p), freeing the entries' buffers (where nothing else holds them) once read.
void place(PointHits&& entries, std::vector<std::uint64_t>&& count, const Partitioning& pt,
           std::uint64_t n, PayloadSink& sink);

}  // namespace

ByteBuffer Hash14Table::build(const RawHits& hits) {
    BufferSink sink;
    write(RawHits(hits), sink);  // shares the hits' storage: frees nothing of the caller's
    return sink.take();
}

void Hash14Table::write(RawHits&& hits, PayloadSink& sink) {
    const std::uint64_t n = hits.size();
    const Partitioning pt(n);
    std::vector<std::uint64_t> count(hits.chunks.size() * pt.parts, 0);
    PointHits entries = compact_hits(std::move(hits), [&](const RawHit& h, std::size_t c) {
        if (h.a >= kMaxPoints || h.b >= kMaxPoints)
            throw std::length_error("hash14: point id over 16 bits");
        ++count[c * pt.parts + pt.part(h.a, h.b)];
        return Sorted{static_cast<std::uint16_t>(h.a), static_cast<std::uint16_t>(h.b),
                      quantise_t16(h.t), h.nu, h.nv};
    });
    place(std::move(entries), std::move(count), pt, n, sink);
}

void Hash14Table::write(PointHits&& hits, PayloadSink& sink) {
    const std::uint64_t n = hits.size();
    const Partitioning pt(n);
    std::vector<std::uint64_t> count(hits.chunks.size() * pt.parts, 0);
    tbb::parallel_for(std::size_t{0}, hits.chunks.size(), [&](std::size_t c) {
        std::uint64_t* row = &count[c * pt.parts];
        for (const PointHit& h : hits.chunks[c]) {
            if (h.a >= kMaxPoints || h.b >= kMaxPoints)
                throw std::length_error("hash14: point id over 16 bits");
            ++row[pt.part(h.a, h.b)];
        }
    });
    place(std::move(hits), std::move(count), pt, n, sink);
}

namespace {

void place(PointHits&& entries, std::vector<std::uint64_t>&& count, const Partitioning& pt,
           std::uint64_t n, PayloadSink& sink) {
    const std::uint64_t buckets = pt.buckets, parts = pt.parts;
    auto part_of = [](std::uint64_t bucket) { return bucket >> kPartBits; };
    // An entry's bucket within its partition.
    auto local_of = [&](const Sorted& e) { return pt.bucket(e.a, e.b) & kLocal; };
    const std::size_t nchunks = entries.chunks.size();
    // Stable positions: partition by partition, chunk by chunk. Each partition's total first,
    // then each chunk's start in it, made in place of the counts; ranges of partitions in
    // parallel, reading the counts row by row (a partition's counts lie a row apart).
    std::vector<std::uint64_t> part_start(parts + 1, 0);
    std::vector<std::uint64_t>& offset = count;
    constexpr std::uint64_t kRange = 256;  // partitions
    tbb::parallel_for(std::uint64_t{0}, parts, kRange, [&](std::uint64_t p0) {
        const std::uint64_t p1 = std::min(parts, p0 + kRange);
        for (std::size_t c = 0; c < nchunks; ++c)
            for (std::uint64_t p = p0; p < p1; ++p) part_start[p + 1] += count[c * parts + p];
    });
    for (std::uint64_t p = 0; p < parts; ++p) part_start[p + 1] += part_start[p];
    tbb::parallel_for(std::uint64_t{0}, parts, kRange, [&](std::uint64_t p0) {
        const std::uint64_t p1 = std::min(parts, p0 + kRange);
        std::vector<std::uint64_t> pos(part_start.begin() + static_cast<std::ptrdiff_t>(p0),
                                       part_start.begin() + static_cast<std::ptrdiff_t>(p1));
        for (std::size_t c = 0; c < nchunks; ++c)
            for (std::uint64_t p = p0; p < p1; ++p) {
                const std::uint64_t here = count[c * parts + p];
                offset[c * parts + p] = pos[p - p0];
                pos[p - p0] += here;
            }
    });
    // The sorted copy is filled a buffer of entries at a time, each buffer freed once read, in
    // small pages: every partition's range fills from its start, so the pages a buffer's entries
    // first touch are about as many as the last buffer gave back (a first touch of memory the
    // process has just freed is cheap; of memory new to it, dear).
    ByteBuffer sorted_buf(n * sizeof(Sorted), ByteBuffer::Pages::kSmall);
    auto* sorted = reinterpret_cast<Sorted*>(sorted_buf.data());
    const std::vector<std::vector<std::size_t>> in_buffer = chunks_by_buffer(entries);
    for (std::size_t j = 0; j < in_buffer.size(); ++j) {
        const std::vector<std::size_t>& cs = in_buffer[j];
        tbb::parallel_for(std::size_t{0}, cs.size(), [&](std::size_t i) {
            const std::size_t c = cs[i];
            std::uint64_t* off = &offset[c * parts];
            for (const Sorted& e : entries.chunks[c]) sorted[off[part_of(pt.bucket(e.a, e.b))]++] = e;
        });
        entries.storage[j].reset();
    }
    entries = {};
    // Which buckets are used, per partition (partition p owns buckets [b0(p), b0(p + 1))), fixes
    // every partition's overflow area before anything is placed.
    auto b0 = [&](std::uint64_t p) { return std::min(buckets, p << kPartBits); };
    std::vector<std::uint64_t> over_count(parts, 0);
    tbb::parallel_for(std::uint64_t{0}, parts, [&](std::uint64_t p) {
        std::uint64_t used[(1u << kPartBits) / 64] = {};
        std::uint64_t distinct = 0;
        for (std::uint64_t i = part_start[p]; i < part_start[p + 1]; ++i) {
            const auto k = static_cast<unsigned>(local_of(sorted[i]));
            distinct += !(used[k / 64] >> (k % 64) & 1);
            used[k / 64] |= std::uint64_t{1} << (k % 64);
        }
        over_count[p] = (part_start[p + 1] - part_start[p]) - distinct;
    });
    std::vector<std::uint64_t> over_start(parts + 1, buckets);
    for (std::uint64_t p = 0; p < parts; ++p) over_start[p + 1] = over_start[p] + over_count[p];

    // The payload, a group of partitions at a time: each group's buckets and overflow entries
    // are two contiguous ranges of it, built in one of two buffers, then handed to the sink
    // while the next group is built in the other (the write is one thread's work).
    sink.reserve(kHeader + over_start[parts] * sizeof(Hash14Entry));
    sink.write_at(0, &buckets, kHeader);
    constexpr std::uint64_t kGroup = 64;  // partitions: about 8 MB of entries
    std::uint64_t most = 0;
    for (std::uint64_t g = 0; g < parts; g += kGroup) {
        const std::uint64_t g1 = std::min(parts, g + kGroup);
        most = std::max(most, (b0(g1) - b0(g)) + (over_start[g1] - over_start[g]));
    }
    ByteBuffer stage_bufs[2] = {ByteBuffer(most * sizeof(Hash14Entry)),
                                ByteBuffer(most * sizeof(Hash14Entry))};
    tbb::task_group writing;  // destroyed first: it waits for its write before the buffers go
    for (std::uint64_t g = 0; g < parts; g += kGroup) {
        const std::uint64_t g1 = std::min(parts, g + kGroup);
        const std::uint64_t nb = b0(g1) - b0(g);
        auto* stage = reinterpret_cast<Hash14Entry*>(stage_bufs[g / kGroup % 2].data());
        // The stage holds the group's buckets, then its overflow entries.
        Hash14Entry* const over_stage = stage + nb;
        tbb::parallel_for(g, g1, [&](std::uint64_t p) {
            Hash14Entry* part_out = stage + (b0(p) - b0(g));
            for (std::uint64_t k = 0; k < b0(p + 1) - b0(p); ++k)
                part_out[k] = {0xFFFF, 0xFFFF, 0, 0, 0, Hash14Table::kEnd};
            std::uint64_t next_over = over_start[p];
            for (std::uint64_t i = part_start[p]; i < part_start[p + 1]; ++i) {
                const Sorted& h = sorted[i];
                const Hash14Entry e{h.a, h.b, h.t, h.nu, h.nv, Hash14Table::kEnd};
                Hash14Entry& head = part_out[local_of(h)];
                if (head.a == 0xFFFF) {
                    head = e;
                    continue;
                }
                // Collisions go right after the bucket's head in its chain.
                Hash14Entry& slot = over_stage[next_over - over_start[g]];
                slot = e;
                slot.next = head.next;
                head.next = static_cast<std::uint32_t>(next_over++);
            }
        });
        writing.wait();  // the previous group's write, from the other buffer (rethrows its error)
        writing.run([&sink, &b0, &over_start, stage, nb, g, g1] {
            sink.write_at(kHeader + b0(g) * sizeof(Hash14Entry), stage, nb * sizeof(Hash14Entry));
            sink.write_at(kHeader + over_start[g] * sizeof(Hash14Entry), stage + nb,
                          (over_start[g1] - over_start[g]) * sizeof(Hash14Entry));
        });
    }
    writing.wait();
}

}  // namespace

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
    // Every chain link must stay inside the table (a corrupt file must not crash lookups).
    for (std::uint64_t k = 0; k < total; ++k)
        if (e_[k].next != kEnd && (e_[k].next >= total || e_[k].next < buckets_))
            throw std::runtime_error("hash14: overflow chain out of range");
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
    return false;  // a cycle in a corrupt table
}

}  // namespace lat
