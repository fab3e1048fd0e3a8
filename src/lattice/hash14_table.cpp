#include "lattice/hash14_table.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

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

}  // namespace

std::vector<std::uint8_t> Hash14Table::build(std::span<const RawHit> hits) {
    const std::uint64_t n = hits.size();
    const std::uint64_t buckets = std::max<std::uint64_t>(1, n / 2);
    // Counting sort of the hits by bucket, so every chain is laid out contiguously.
    std::vector<std::uint32_t> start(buckets + 1, 0);
    std::vector<std::uint64_t> bucket(n);
    for (std::uint64_t i = 0; i < n; ++i) {
        if (hits[i].a >= kMaxPoints || hits[i].b >= kMaxPoints)
            throw std::length_error("hash14: point id over 16 bits");
        bucket[i] = bucket_of(hits[i].a, hits[i].b, buckets);
        ++start[bucket[i] + 1];
    }
    for (std::uint64_t k = 0; k < buckets; ++k) start[k + 1] += start[k];
    std::uint64_t used_buckets = 0;
    for (std::uint64_t k = 0; k < buckets; ++k) used_buckets += start[k + 1] > start[k];
    const std::uint64_t total = buckets + (n - used_buckets);

    std::vector<std::uint8_t> payload(kHeader + total * sizeof(Hash14Entry));
    std::memcpy(payload.data(), &buckets, 8);
    auto* e = reinterpret_cast<Hash14Entry*>(payload.data() + kHeader);
    for (std::uint64_t k = 0; k < buckets; ++k) e[k] = {0xFFFF, 0xFFFF, 0, 0, 0, kEnd};

    // Overflow slots: bucket k's extra entries at a running offset.
    std::vector<std::uint32_t> order(n);
    {
        std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
        for (std::uint64_t i = 0; i < n; ++i) order[fill[bucket[i]]++] = static_cast<std::uint32_t>(i);
    }
    std::uint64_t overflow = buckets;
    for (std::uint64_t k = 0; k < buckets; ++k) {
        std::uint64_t prev = k;
        for (std::uint32_t j = start[k]; j < start[k + 1]; ++j) {
            const RawHit& h = hits[order[j]];
            const std::uint64_t slot = j == start[k] ? k : overflow++;
            const auto t = static_cast<std::uint16_t>(std::lround(std::clamp(double(h.t), 0.0, 1.0) * 65535.0));
            // Re-encode the 16-bit raw normal at 16 bits: exact copy.
            e[slot] = {static_cast<std::uint16_t>(h.a), static_cast<std::uint16_t>(h.b), t, h.nu, h.nv, kEnd};
            if (slot != k) e[prev].next = static_cast<std::uint32_t>(slot);
            prev = slot;
        }
    }
    return payload;
}

Hash14Table::Hash14Table(const std::uint8_t* payload, std::size_t size, std::uint64_t entries)
    : entries_(entries), size_(size) {
    if (size < kHeader) throw std::runtime_error("hash14: payload too small");
    std::memcpy(&buckets_, payload, 8);
    const std::size_t need = kHeader + buckets_ * sizeof(Hash14Entry);
    if (buckets_ == 0 || need > size || (size - kHeader) % sizeof(Hash14Entry) != 0)
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
