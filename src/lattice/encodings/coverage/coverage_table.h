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
// empty slot's record says so), the groups in slot order, with a bit per group saying whether
// it is kept. Read through rank lines built at open (a line: the rank of its first bit and 448
// bits, 1 MB at sigma^-1 = 4 for Plate 4's hair, 1/14 of the lines of one bit per pair), a
// pair's record is found from a line that is often in cache, then read: about one cache miss
// a pair instead of two.
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
    // A line of the kept-group bits: the rank of its first bit and the 448 that follow.
    struct alignas(64) RankLine {
        static constexpr std::uint64_t kWords = 7, kBits = kWords * 64;
        std::uint64_t base;  // kept groups before this line's first
        std::uint64_t bits[kWords];
    };
    static_assert(sizeof(RankLine) == 64);
    static constexpr int kGroupSlots = 16;
    static constexpr std::size_t kGroupBytes = kGroupSlots * kRecordBytes;
    PairIndex index_;
    std::unique_ptr<RankLine[]> lines_;
    const std::uint8_t* groups_ = nullptr;
    std::uint64_t occupied_ = 0, kept_groups_ = 0;
    std::uint64_t entries_;
    std::size_t size_;  // the payload's and the rank lines'
    // Coverage statistics for `inspect`, gathered when the records are checked at open.
    std::uint64_t partial_ = 0;
    double alpha_sum_ = 0;

    std::uint64_t build_lines(const std::uint64_t* kept, std::uint64_t nwords);
    void check_records(const std::uint64_t* kept);
    const std::uint8_t* record(std::uint32_t a, std::uint32_t b) const;
    // The record of slot s (below index_.slots()) when its group is kept, else null; it may
    // still be an empty slot's (stored() says).
    const std::uint8_t* record_at(std::uint64_t s) const {
        const std::uint64_t g = s / kGroupSlots;
        const RankLine& l = lines_[g / RankLine::kBits];
        const auto off = static_cast<unsigned>(g % RankLine::kBits);
        const unsigned w = off >> 6, bit = off & 63;
        const std::uint64_t word = l.bits[w];
        if (!((word >> bit) & 1)) return nullptr;
        std::uint64_t r = l.base + static_cast<std::uint64_t>(
                                       std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
        for (unsigned k = 0; k < w; ++k) r += static_cast<std::uint64_t>(std::popcount(l.bits[k]));
        return groups_ + r * kGroupBytes + (s % kGroupSlots) * kRecordBytes;
    }
    static bool stored(const std::uint8_t* r);
    static void decode(const std::uint8_t* r, CoverageHit& hit, bool normal);
};

}  // namespace lat
