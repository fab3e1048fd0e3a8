#pragma once
// `coverage`: a prefiltered table. Per ordered pair of boundary points it keeps the
// hit of the pair's own segment, as every table does (lookup: what point sampling, CSG, inside
// tests and certification use), and the pair's coverage (lattice/coverage.h): the share of the
// sub-rays snapping to the pair that meet the primitive and their mean hit, which filtered
// rendering uses. The hit is a record of 16-bit fields: its t and normal (6 bytes); the coverage
// a 32-bit word (4 bytes): alpha in 1/255, the mean t in 1/511, the mean normal's direction
// octahedral in 6 + 6 bits (at most 2.6 degrees off) and how far the normals spread about it
// in 3 bits (CoverageSample::spread, in steps of 1/7). A coverage is a mean over a cell-wide
// bundle, blended with its neighbours, so its direction and t need few bits; the spread is
// what shades a hair thinner than a cell right: its mean normal is about pi/4 long, and read
// as a unit vector its diffuse light was a quarter too bright (0.5 to 1.6 dB at a million
// hairs: bench/notes/scale-log.md).
//
// Pairs are filed in slots where neighbours in ray space are neighbours in memory (pair_index.h:
// tiles of 256 slots, each 16 consecutive slots a 2 x 2 x 2 x 2 cell of the 4-D grid of entry
// and exit points). Records are kept densely for every group of 16 slots that holds a stored
// pair (an empty slot's records say so), with a bit per group saying whether it is kept; the
// groups' coverage records (64 bytes a group: one cache line) apart from their hits, which
// filtered rendering does not read. Read through rank lines built at open (a line: 16 tiles'
// bits and their ranks; 1.75 MB at sigma^-1 = 4 for Plate 4's hair, where one bit per pair
// took 16 MB), a pair's record is found from a line that is often in cache: about one cache
// miss a pair instead of two, and a rank in one read and one popcount.
#include <bit>
#include <cstdint>
#include <memory>

#include "lattice/coverage.h"
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
    // A handle is the address of the pair's coverage record, 0 when it has none.
    void locate_coverage(const std::uint32_t* a, const std::uint32_t* b, int n,
                         std::uint64_t* ref) const override;
    void coverage_at(const std::uint64_t* ref, int n, CoverageHit* out, bool* found,
                     bool normals) const override;
    std::string encoding() const override { return "coverage"; }
    std::string details() const override;
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override { return size_; }

    // The fields of a pair's hit record, 16 bits each.
    enum Field { kT, kNu, kNv, kFields };
    static constexpr std::size_t kHitBytes = kFields * 2, kCoverBytes = 4;
    static constexpr std::uint16_t kNoHit = 0xFFFF;  // kT of a pair whose own segment misses
    static constexpr int kGroupSlots = PairIndex::kCellSlots;
    // A coverage record's fields: their widths in bits, from bit 0 up in this order.
    static constexpr int kAlphaBits = 8, kMeanTBits = 9, kMeanNormalBits = 6, kSpreadBits = 3;
    static_assert(kAlphaBits + kMeanTBits + 2 * kMeanNormalBits + kSpreadBits == 8 * kCoverBytes);
    // A sample (alpha > 0) as its record, and a record back (alpha 0: no coverage). normal:
    // false when only alpha and t are wanted.
    static std::uint32_t pack_cover(const CoverageSample& c);
    static void unpack_cover(std::uint32_t cover, CoverageHit& hit, bool normal);

private:
    // A line of the kept-group bits, by tile (PairIndex::kTileSlots, 16 groups: 16 bits of a
    // word of them): 16 tiles' bits, and the ranks of the line's first group and of each tile's
    // first within the line, so that a group's rank is one read and one popcount.
    struct alignas(64) RankLine {
        static constexpr unsigned kTiles = 16;
        std::uint64_t base;            // kept groups before this line's first
        std::uint16_t kept[kTiles];    // bit j of kept[i]: group j of tile i is kept
        std::uint8_t before[kTiles];   // kept groups in this line before tile i (at most 240)
    };
    static_assert(sizeof(RankLine) == 64);
    static constexpr unsigned kTileGroups = PairIndex::kTileSlots / kGroupSlots;
    static_assert(kTileGroups == 16);
    // Where a slot's records are: its group's rank among the kept ones, and its place in it.
    struct Place {
        std::uint64_t group;
        unsigned slot;
        bool kept;
    };
    PairIndex index_;
    std::unique_ptr<RankLine[]> lines_;
    const std::uint8_t* covers_ = nullptr;  // kGroupSlots coverage records a kept group
    const std::uint8_t* hits_ = nullptr;    // kGroupSlots hit records a kept group
    std::uint64_t occupied_ = 0, kept_groups_ = 0;
    int rays_ = 0;  // sub-rays a pair
    std::uint64_t entries_;
    std::size_t size_;  // the payload's and the rank lines'
    // Coverage statistics for `inspect`, gathered when the records are checked at open.
    std::uint64_t partial_ = 0;
    double alpha_sum_ = 0;

    std::uint64_t build_lines(const std::uint64_t* kept, std::uint64_t nwords);
    void check_records(const std::uint64_t* kept);
    Place place(std::uint32_t a, std::uint32_t b) const;
    Place place_of(std::uint64_t s) const {
        const std::uint64_t g = s / kGroupSlots, tile = g / kTileGroups;
        const RankLine& l = lines_[tile / RankLine::kTiles];
        const auto i = static_cast<unsigned>(tile % RankLine::kTiles);
        const auto bit = static_cast<unsigned>(g % kTileGroups);
        const unsigned kept = l.kept[i];
        if (!((kept >> bit) & 1u)) return {0, 0, false};
        const auto below = static_cast<unsigned>(std::popcount(kept & ((1u << bit) - 1)));
        return {l.base + l.before[i] + below, static_cast<unsigned>(s % kGroupSlots), true};
    }
    // A coverage handle (the record's address, 0 for none) for a slot (or PairIndex::kNone).
    // The records are found through the rank lines (often in cache) and prefetched, so that
    // the cache misses of a blend's pairs overlap instead of following one another.
    std::uint64_t locate(std::uint64_t slot) const {
        const Place p = slot == PairIndex::kNone ? Place{0, 0, false} : place_of(slot);
        if (!p.kept) return 0;
        const std::uint8_t* c = cover_at(p);
        __builtin_prefetch(c);
        return reinterpret_cast<std::uintptr_t>(c);
    }
    const std::uint8_t* cover_at(const Place& p) const {
        return covers_ + (p.group * kGroupSlots + p.slot) * kCoverBytes;
    }
    const std::uint8_t* hit_at(const Place& p) const {
        return hits_ + (p.group * kGroupSlots + p.slot) * kHitBytes;
    }
};

}  // namespace lat
