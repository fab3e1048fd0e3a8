#pragma once
// `coverage`: a prefiltered table (issue 10). Per ordered pair of boundary points it keeps the
// hit of the pair's own segment, as every table does (lookup: what point sampling, CSG, inside
// tests and certification use), and the pair's coverage (lattice/coverage.h): the share of the
// sub-rays snapping to the pair that meet the primitive and their mean hit, which filtered
// rendering uses. Pairs are indexed densely, a * N + b for N boundary points, by occupancy bits
// and a rank directory (read through rank lines built at open); a record is seven 16-bit fields
// (alpha in 1/65535).
#include <bit>
#include <cstdint>
#include <memory>

#include "lattice/bits/bit_array.h"
#include "lattice/boundary_grid.h"
#include "lattice/encoding.h"
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
    // The occupancy bits as rendering reads them: a cache line holds the rank of its first bit
    // and the 448 bits that follow, so that finding a pair's record takes one line besides the
    // record (the file's occupancy words and rank directory, apart, took two: each a cache miss
    // in tables of hundreds of MB). Built from the file's (checked) ones at open.
    struct alignas(64) RankLine {
        static constexpr std::uint64_t kWords = 7, kBits = kWords * 64;
        std::uint64_t base;  // set bits before this line's first
        std::uint64_t bits[kWords];
    };
    static_assert(sizeof(RankLine) == 64);
    std::uint32_t points_ = 0;
    std::uint64_t occupied_ = 0;
    std::unique_ptr<RankLine[]> lines_;
    const std::uint8_t* records_ = nullptr;
    std::uint64_t entries_;
    std::size_t size_;  // the payload's and the rank lines'
    // Coverage statistics for `inspect`, gathered when the records are checked at open.
    std::uint64_t partial_ = 0;
    double alpha_sum_ = 0;

    const std::uint8_t* record(std::uint32_t a, std::uint32_t b) const;
    // The record of dense pair index i (below points_^2), or null when the pair is not stored.
    const std::uint8_t* record_at(std::uint64_t i) const {
        const RankLine& l = lines_[i / RankLine::kBits];
        const auto off = static_cast<unsigned>(i % RankLine::kBits);
        const unsigned w = off >> 6, bit = off & 63;
        const std::uint64_t word = l.bits[w];
        if (!((word >> bit) & 1)) return nullptr;
        std::uint64_t r = l.base + static_cast<std::uint64_t>(
                                       std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
        for (unsigned k = 0; k < w; ++k) r += static_cast<std::uint64_t>(std::popcount(l.bits[k]));
        return records_ + r * kRecordBytes;
    }
    const RankLine* line_of(std::uint64_t i) const { return &lines_[i / RankLine::kBits]; }
    // The dense index of pair (a, b), or ~0 when a point is out of range.
    std::uint64_t pair_index(std::uint32_t a, std::uint32_t b) const {
        return a < points_ && b < points_ ? static_cast<std::uint64_t>(a) * points_ + b : ~0ull;
    }
    static void decode(const std::uint8_t* r, CoverageHit& hit, bool normal);
};

}  // namespace lat
