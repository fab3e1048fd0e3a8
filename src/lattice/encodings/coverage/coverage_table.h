#pragma once
// `coverage`: a prefiltered table (issue 10). Per ordered pair of boundary points it keeps the
// hit of the pair's own segment, as every table does (lookup: what point sampling, CSG, inside
// tests and certification use), and the pair's coverage (lattice/coverage.h): the share of the
// sub-rays snapping to the pair that meet the primitive and their mean hit, which filtered
// rendering uses. Pairs are indexed densely, a * N + b for N boundary points, by occupancy bits
// and a rank directory; a record is seven 16-bit fields (alpha in 1/65535).
#include <cstdint>

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
                       bool* found) const override;
    void prefetch_coverage(const std::uint32_t* a, const std::uint32_t* b, int n) const override;
    std::string encoding() const override { return "coverage"; }
    std::string details() const override;
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override { return size_; }

    // The record fields, in this order.
    enum Field { kT, kNu, kNv, kMeanT, kMeanNu, kMeanNv, kAlpha, kFields };
    static constexpr std::uint16_t kNoHit = 0xFFFF;  // kT of a pair whose own segment misses

private:
    std::uint32_t points_ = 0;
    std::uint64_t occupied_ = 0;
    RankIndex rank_;
    const std::uint64_t* occ_ = nullptr;
    const std::uint32_t* counts_ = nullptr;
    const std::uint8_t* records_ = nullptr;
    std::uint64_t entries_;
    std::size_t size_;
    // Coverage statistics for `inspect`, gathered when the records are checked at open.
    std::uint64_t partial_ = 0;
    double alpha_sum_ = 0;

    const std::uint8_t* record(std::uint32_t a, std::uint32_t b) const;
    // The dense index of pair (a, b), or ~0 when a point is out of range.
    std::uint64_t pair_index(std::uint32_t a, std::uint32_t b) const {
        return a < points_ && b < points_ ? static_cast<std::uint64_t>(a) * points_ + b : ~0ull;
    }
    static void decode(const std::uint8_t* r, CoverageHit& hit);
};

}  // namespace lat
