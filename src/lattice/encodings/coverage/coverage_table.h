#pragma once
// `coverage`: a prefiltered table (issue 10). Per ordered pair of boundary points it keeps the
// hit of the pair's own segment, as every table does (lookup: what point sampling, CSG, inside
// tests and certification use), and the pair's coverage (lattice/coverage.h): the share of the
// sub-rays snapping to the pair that meet the primitive and their mean hit, which filtered
// rendering uses. Pairs are filed in slots where neighbours in ray space are neighbours in
// memory (pair_index.h), with occupancy bits read through rank lines built at open, and records
// in slot order; a record is seven 16-bit fields (alpha in 1/65535).
#include <bit>
#include <cstdint>
#include <memory>

#include "lattice/bits/bit_array.h"
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
    // The occupancy bits as rendering reads them: a cache line holds the rank of a tile's
    // first slot and the tile's 256 bits, so that finding a pair's record takes one line
    // besides the record, and a blend's pairs, in one or two tiles, one or two lines. Built
    // from the file's (checked) occupancy words at open.
    struct alignas(64) RankLine {
        std::uint64_t base;  // set bits before this tile's first
        std::uint64_t bits[PairIndex::kTileWords];
    };
    static_assert(sizeof(RankLine) == 64);
    PairIndex index_;
    std::uint64_t occupied_ = 0;
    std::unique_ptr<RankLine[]> lines_;
    const std::uint8_t* records_ = nullptr;
    std::uint64_t entries_;
    std::size_t size_;  // the payload's and the rank lines'
    // Coverage statistics for `inspect`, gathered when the records are checked at open.
    std::uint64_t partial_ = 0;
    double alpha_sum_ = 0;

    void build_lines(const std::uint64_t* occ);
    const std::uint8_t* record(std::uint32_t a, std::uint32_t b) const;
    // The record of slot s (below index_.slots()), or null when the pair is not stored.
    const std::uint8_t* record_at(std::uint64_t s) const {
        const RankLine& l = lines_[s / PairIndex::kTileSlots];
        const auto off = static_cast<unsigned>(s % PairIndex::kTileSlots);
        const unsigned w = off >> 6, bit = off & 63;
        const std::uint64_t word = l.bits[w];
        if (!((word >> bit) & 1)) return nullptr;
        std::uint64_t r = l.base + static_cast<std::uint64_t>(
                                       std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
        for (unsigned k = 0; k < w; ++k) r += static_cast<std::uint64_t>(std::popcount(l.bits[k]));
        return records_ + r * kRecordBytes;
    }
    const RankLine* line_of(std::uint64_t s) const { return &lines_[s / PairIndex::kTileSlots]; }
    static void decode(const std::uint8_t* r, CoverageHit& hit, bool normal);
};

}  // namespace lat
