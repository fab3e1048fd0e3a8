#pragma once
// `coverage`: a prefiltered table (issue 10). Per ordered pair of boundary points it keeps the
// hit of the pair's own segment, as every table does (lookup: what point sampling, CSG, inside
// tests and certification use), and the pair's coverage (lattice/coverage.h): the share of the
// sub-rays snapping to the pair that meet the primitive and their mean hit, which filtered
// rendering uses. A record is seven 16-bit fields (alpha in 1/65535).
//
// Pairs are filed in slots where neighbours in ray space are neighbours in memory (pair_index.h:
// tiles of 256 slots, each 16 consecutive slots a 2 x 2 x 2 x 2 cell of the 4-D grid of entry
// and exit points). Records are kept densely for every group of 16 slots that holds any (an
// empty slot's record says so), the groups in slot order; a directory built at open gives
// each tile its first group and which of its 16 groups are kept. A pair's record is then found
// from the directory alone (a few MB, mostly in cache): one cache miss a pair, not two (an
// occupancy line, then the record, as the rank lines of a * N + b indexing needed).
#include <bit>
#include <cstdint>
#include <memory>

#include "lattice/encoding.h"
#include "lattice/encodings/coverage/pair_index.h"
#include "lattice/table.h"

namespace lat {

class CoverageTable final : public LatticeTable {
public:
    static ByteBuffer build(const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt);
    CoverageTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                  const TableContext& ctx);

    bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const override;
    bool coverage(std::uint32_t a, std::uint32_t b, CoverageHit& hit) const override;
    void coverage_many(const std::uint32_t* a, const std::uint32_t* b, int n, CoverageHit* out,
                       bool* found, bool normals) const override;
    void prefetch_coverage(const std::uint32_t* a, const std::uint32_t* b, int n) const override;
    std::string encoding() const override { return "coverage"; }
    std::string details() const override;
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override { return size_; }

    // The record fields, in this order.
    enum Field { kT, kNu, kNv, kMeanT, kMeanNu, kMeanNv, kAlpha, kFields };
    static constexpr std::size_t kRecordBytes = kFields * 2;
    static constexpr std::uint16_t kNoHit = 0xFFFF;  // kT of a pair whose own segment misses

private:
    // A tile's entry in the directory: its first kept group and a bit per kept group.
    struct TileEntry {
        std::uint32_t first;
        std::uint16_t kept;
        std::uint16_t unused;
    };
    static constexpr int kGroupSlots = 16;
    static constexpr std::size_t kGroupBytes = kGroupSlots * kRecordBytes;
    PairIndex index_;
    std::unique_ptr<TileEntry[]> tiles_;
    const std::uint8_t* groups_ = nullptr;
    std::uint64_t occupied_ = 0, kept_groups_ = 0;
    std::uint64_t entries_;
    std::size_t size_;  // the payload's and the directory's
    // Coverage statistics for `inspect`, gathered when the records are checked at open.
    std::uint64_t partial_ = 0;
    double alpha_sum_ = 0;

    void check_groups(const std::uint16_t* kept, std::uint64_t groups);
    void check_records();
    const std::uint8_t* record(std::uint32_t a, std::uint32_t b) const;
    // The record of slot s (below index_.slots()) when its group is kept, else null; it may
    // still be an empty slot's (stored() says).
    const std::uint8_t* record_at(std::uint64_t s) const {
        const TileEntry& e = tiles_[s / PairIndex::kTileSlots];
        const auto inner = static_cast<unsigned>(s % PairIndex::kTileSlots);
        const unsigned g = inner / kGroupSlots;
        if (!((e.kept >> g) & 1u)) return nullptr;
        const std::uint64_t k = e.first + static_cast<unsigned>(std::popcount(
                                              static_cast<unsigned>(e.kept) & ((1u << g) - 1)));
        return groups_ + k * kGroupBytes + (inner % kGroupSlots) * kRecordBytes;
    }
    static bool stored(const std::uint8_t* r);
    static void decode(const std::uint8_t* r, CoverageHit& hit, bool normal);
};

}  // namespace lat
