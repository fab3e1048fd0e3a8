#pragma once
// The paper's Lattice Hash Table (section 2.3) in its 14-byte entry:
//   key   a, b : 2 x 16 bits  boundary point ids of p_i and p_o (kept: the hash is not perfect)
//   t          : 16 bits      the hit as p_i + t (p_o - p_i), t quantised to 1/65535
//   normal     : 2 x 16 bits  octahedral encoding (angle error below 0.01 degrees)
//   next       : 32 bits      overflow chain: index of the next entry, or none
// Buckets are the first M entries (M = N/2 for N hits); colliding entries go to the overflow
// area, linked from their bucket. The point lies exactly on the segment, so its error is
// at most |p_o - p_i| / 131070 (below 0.001 cells for the hair at sigma^-1 = 4).
#include <cstdint>
#include <vector>

#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

class PayloadSink;

#pragma pack(push, 1)
struct Hash14Entry {
    std::uint16_t a, b;
    std::uint16_t t;
    std::uint16_t nu, nv;
    std::uint32_t next;
};
#pragma pack(pop)
static_assert(sizeof(Hash14Entry) == 14);

class Hash14Table final : public LatticeTable {
public:
    static constexpr std::uint32_t kMaxPoints = 0xFFFF;  // id 0xFFFF marks an empty bucket
    static constexpr std::uint32_t kEnd = 0xFFFFFFFFu;

    // From rasterized hits; every id must be below kMaxPoints. Parallel; the payload does not
    // depend on the thread count.
    static ByteBuffer build(const RawHits& hits);
    // The same payload into a sink, freeing the hits (where nothing else holds them) once read.
    static void write(RawHits&& hits, PayloadSink& sink);
    // The same from hits rasterized as PointHits.
    static void write(PointHits&& hits, PayloadSink& sink);
    // Over a payload made by build (owned or memory-mapped; it must outlive the table).
    Hash14Table(const std::uint8_t* payload, std::size_t size, std::uint64_t entries);

    bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const override;
    std::string encoding() const override { return "hash14"; }
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override { return size_; }

private:
    const Hash14Entry* e_;
    std::uint64_t buckets_;
    std::uint64_t entries_;
    std::size_t size_;
};

}  // namespace lat
