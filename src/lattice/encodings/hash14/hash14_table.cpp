#include "lattice/encodings/hash14/hash14_table.h"

#include <tbb/parallel_for.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
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
// bucket is hashed again where it is needed rather than kept: at 10 bytes, the half of a raw
// hit that compaction frees holds the whole sorted copy.
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
// their entries are placed, and partitions into groups (16: about 1.3 MB of entries and 2 MB of
// payload, near what a core's cache holds). Entries are sorted stably by group (one pass over
// memory, to few places), then each group by partition in a buffer of its own thread's, which
// the placement reads while it is still in cache.
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
    std::uint64_t part(const Sorted& e) const { return bucket(e) >> kPartBits; }
    // Partition p owns buckets [b0(p), b0(p + 1)); group g partitions [p0(g), p0(g + 1)).
    std::uint64_t b0(std::uint64_t p) const { return std::min(buckets, p << kPartBits); }
    std::uint64_t p0(std::uint64_t g) const { return std::min(parts, g * kGroup); }
};

// What the placement needs to know before it starts: where each partition's entries start in
// the sorted order (part_start, parts + 1 values) and its overflow entries in the payload
// (over_start), and where each chunk's entries of each group go (group_pos[c * groups + g]).
struct Layout {
    std::vector<std::uint64_t> part_start, over_start, group_pos;
};

// One pass over the entries: each chunk's count in each partition, and which buckets are used
// (bitsets per thread, or'ed).
Layout count_entries(const PointHits& entries, const Partitioning& pt) {
    const std::size_t nchunks = entries.chunks.size();
    const std::uint64_t parts = pt.parts, groups = pt.groups;
    std::vector<std::uint32_t> count(nchunks * parts, 0);  // n < 2^32 (32-bit links)
    const std::size_t words = (pt.buckets + 63) / 64;
    tbb::enumerable_thread_specific<std::vector<std::uint64_t>> used_by_thread(words, 0);
    tbb::parallel_for(std::size_t{0}, nchunks, [&](std::size_t c) {
        std::vector<std::uint64_t>& used = used_by_thread.local();
        std::uint32_t* row = &count[c * parts];
        for (const Sorted& e : entries.chunks[c]) {
            if (e.a >= Hash14Table::kMaxPoints || e.b >= Hash14Table::kMaxPoints)
                throw std::length_error("hash14: point id over 16 bits");
            const std::uint64_t b = pt.bucket(e);
            ++row[b >> kPartBits];
            used[b / 64] |= std::uint64_t{1} << (b % 64);
        }
    });
    std::vector<std::uint64_t> used(words, 0);
    for (const std::vector<std::uint64_t>& u : used_by_thread)
        for (std::size_t w = 0; w < words; ++w) used[w] |= u[w];

    Layout l;
    l.part_start.assign(parts + 1, 0);
    for (std::size_t c = 0; c < nchunks; ++c)  // row by row: the counts lie in that order
        for (std::uint64_t p = 0; p < parts; ++p) l.part_start[p + 1] += count[c * parts + p];
    // Overflow entries: a partition's entries less its used buckets (b0(p) is a multiple of 64).
    l.over_start.assign(parts + 1, pt.buckets);
    for (std::uint64_t p = 0; p < parts; ++p) {
        std::uint64_t distinct = 0;
        for (std::uint64_t w = pt.b0(p) / 64; w < (pt.b0(p + 1) + 63) / 64; ++w)
            distinct += static_cast<std::uint64_t>(__builtin_popcountll(used[w]));
        l.over_start[p + 1] = l.over_start[p] + l.part_start[p + 1] - distinct;
    }
    for (std::uint64_t p = 0; p < parts; ++p) l.part_start[p + 1] += l.part_start[p];
    // Stable by group: group by group, chunk by chunk.
    l.group_pos.resize(nchunks * groups);
    std::vector<std::uint64_t> pos(groups);
    for (std::uint64_t g = 0; g < groups; ++g) pos[g] = l.part_start[pt.p0(g)];
    for (std::size_t c = 0; c < nchunks; ++c)
        for (std::uint64_t g = 0; g < groups; ++g) {
            l.group_pos[c * groups + g] = pos[g];
            for (std::uint64_t p = pt.p0(g); p < pt.p0(g + 1); ++p) pos[g] += count[c * parts + p];
        }
    return l;
}

// The entries sorted stably by group, a buffer of entries at a time, each buffer freed once
// read (where nothing else holds it), into small pages: every group's range fills from its
// start, so the pages a buffer's entries first touch are about as many as the buffer before
// gave back (a first touch of memory the process has just freed is cheap; of memory new to it,
// dear).
ByteBuffer sort_by_group(PointHits&& entries, const Partitioning& pt, Layout& l) {
    ByteBuffer out(entries.size() * sizeof(Sorted), ByteBuffer::Pages::kSmall);
    auto* sorted = reinterpret_cast<Sorted*>(out.data());
    const std::vector<std::vector<std::size_t>> in_buffer = chunks_by_buffer(entries);
    for (std::size_t j = 0; j < in_buffer.size(); ++j) {
        const std::vector<std::size_t>& cs = in_buffer[j];
        tbb::parallel_for(std::size_t{0}, cs.size(), [&](std::size_t i) {
            const std::size_t c = cs[i];
            std::uint64_t* pos = &l.group_pos[c * pt.groups];
            for (const Sorted& e : entries.chunks[c]) sorted[pos[pt.part(e) / kGroup]++] = e;
        });
        entries.storage[j].reset();
    }
    entries = {};
    return out;
}

// A thread's buffers for one group at a time: its entries by partition, and its payload.
struct GroupScratch {
    ByteBuffer by_part, stage;
};

// Group g's buckets, then its overflow entries, into stage; its entries (sorted by group) by
// partition first. A bucket's first entry is its head; later ones take the next overflow slot
// and go right after the head in its chain.
void place_group(std::uint64_t g, const Sorted* sorted, const Partitioning& pt, const Layout& l,
                 GroupScratch& s) {
    const std::uint64_t q0 = pt.p0(g), q1 = pt.p0(g + 1);
    auto* mine = reinterpret_cast<Sorted*>(s.by_part.data());
    std::uint64_t next[kGroup];
    for (std::uint64_t p = q0; p < q1; ++p) next[p - q0] = l.part_start[p] - l.part_start[q0];
    for (std::uint64_t i = l.part_start[q0]; i < l.part_start[q1]; ++i)
        mine[next[pt.part(sorted[i]) - q0]++] = sorted[i];
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
            Hash14Entry& head = part_out[pt.bucket(h) & kLocal];
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

// The payload from the entries (chunks in entry order), freeing the entries' buffers (where
// nothing else holds them) once read. Groups are placed in parallel, each written as two
// contiguous ranges of the payload (its buckets, its overflow entries).
void place(PointHits&& entries, PayloadSink& sink) {
    const Partitioning pt(entries.size());
    Layout l = count_entries(entries, pt);
    const ByteBuffer sorted_buf = sort_by_group(std::move(entries), pt, l);
    const auto* sorted = reinterpret_cast<const Sorted*>(sorted_buf.data());
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
    tbb::parallel_for(std::uint64_t{0}, pt.groups, [&](std::uint64_t g) {
        GroupScratch& s = scratch.local();
        if (!s.stage.data()) {
            s.by_part = ByteBuffer(most_entries * sizeof(Sorted));
            s.stage = ByteBuffer(most_stage * sizeof(Hash14Entry));
        }
        place_group(g, sorted, pt, l, s);
        const std::uint64_t q0 = pt.p0(g), q1 = pt.p0(g + 1), nb = pt.b0(q1) - pt.b0(q0);
        const auto* stage = reinterpret_cast<const Hash14Entry*>(s.stage.data());
        const std::lock_guard<std::mutex> lock(writing);
        sink.write_at(kHeader + pt.b0(q0) * sizeof(Hash14Entry), stage, nb * sizeof(Hash14Entry));
        sink.write_at(kHeader + l.over_start[q0] * sizeof(Hash14Entry), stage + nb,
                      (l.over_start[q1] - l.over_start[q0]) * sizeof(Hash14Entry));
    });
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
