#pragma once
// `candidates`: an exact lattice. For each unordered pair {a, b} of boundary points (a = b
// included) the table stores which parts of the primitive any ray that snaps to that pair can
// meet: a snapped segment lies within sqrt(2)/2 cells of its ray inside the box, so these are
// the parts within that distance of the segment p_a p_b (tested exactly for spheres and for the
// capsules around cylinders, through bounding spheres for other shapes). The renderer then
// intersects only those parts, exactly, with the real ray: images equal exact mode, and the
// cost of a ray depends on how many parts lie near it, not on how many the primitive has.
// Layout (payload tag CAND3): occupancy bits with a rank directory over the pairs, then per
// occupied pair the id of its part set (bits chosen per table), then the distinct part sets,
// each stored once as a sorted list of 32-bit part indices (an offset array into one index
// array), so a primitive may have any number of parts.
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/lattice_source.h"
#include "lattice/bits/bit_array.h"
#include "lattice/boundary_grid.h"
#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

class CandidatesTable final : public LatticeTable {
public:
    // Past memory_budget bytes (0: no limit) the build stops with an InputError.
    static ByteBuffer build(const TableContext& ctx, bool progress, std::size_t memory_budget = 0);
    CandidatesTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                    const TableContext& ctx);

    Kind kind() const override { return Kind::kCandidates; }
    bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const override;
    bool candidates(std::uint32_t a, std::uint32_t b, CandidateList& out) const override;
    std::string encoding() const override { return "candidates"; }
    std::string details() const override;
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override { return size_; }

    std::uint64_t pairs_stored() const { return occupied_; }
    std::uint32_t distinct_sets() const { return sets_; }

    // Pairs with lo <= hi.
    static std::uint64_t pair_index(std::uint32_t lo, std::uint32_t hi) {
        return static_cast<std::uint64_t>(hi) * (hi + 1) / 2 + lo;
    }

private:
    RankIndex rank_;
    const std::uint64_t* ids_ = nullptr;
    // sets_ + 1 offsets: set i is parts_[offsets_[i], offsets_[i + 1]).
    const std::uint32_t* offsets_ = nullptr;
    const std::uint32_t* parts_ = nullptr;
    std::uint32_t points_ = 0, set_bits_ = 0, sets_ = 0;
    std::uint64_t occupied_ = 0;
    std::uint64_t entries_;
    std::size_t size_;
    TableContext ctx_;
    std::optional<ShapeSource> primitive_;  // ctx_.primitive's, asked once
    BoundaryGrid grid_;

    void check_lists(std::uint64_t total) const;
};

}  // namespace lat
