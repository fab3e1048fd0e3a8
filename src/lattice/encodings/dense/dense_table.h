#pragma once
// `dense`: a lattice table without hashing. The unordered pair {a, b} of boundary points has a
// dense index (b(b-1)/2 + a for a < b); a bit vector with a rank directory says whether the
// segment meets the primitive and where its record is. A record holds both directions, the
// near hit of a -> b and of b -> a (the far hit of a -> b), so one entry serves both and the
// CSG exit. Each hit is a quantised parameter t along its segment and its normal, either as an
// octahedral code or as the primitive's part that was hit, whose normal is re-evaluated at the
// decoded point. Bit widths are chosen per table, the smallest that meet the error targets
// (EncodeOptions), checked on every stored hit.
#include <cstdint>

#include "lattice/bits/bit_array.h"
#include "lattice/boundary_grid.h"
#include "lattice/encoding.h"
#include "lattice/table.h"

namespace lat {

class DenseTable final : public LatticeTable {
public:
    static ByteBuffer build(const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt);
    DenseTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
               const TableContext& ctx);

    bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const override;
    bool lookup_t(std::uint32_t a, std::uint32_t b, double& t) const override;
    std::string encoding() const override { return "dense"; }
    std::string details() const override;
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override { return size_; }

    struct Layout {
        std::uint32_t points = 0;
        std::uint64_t domain = 0;    // unordered pairs
        std::uint64_t occupied = 0;  // records
        std::uint32_t t_bits = 0;
        std::uint32_t normal_mode = 0;  // 0: octahedral, 1: part
        std::uint32_t normal_bits = 0;  // per hit: 2 x per-component bits, or the part code bits
        std::uint32_t parts = 0;        // part dictionary entries
    };
    const Layout& layout() const { return l_; }

    static std::uint64_t pair_index(std::uint32_t lo, std::uint32_t hi) {
        return static_cast<std::uint64_t>(hi) * (hi - 1) / 2 + lo;
    }

private:
    Layout l_;
    RankIndex rank_;
    const std::uint64_t* records_ = nullptr;
    const std::uint32_t* part_codes_ = nullptr;  // (part, leaf) pairs
    std::uint64_t entries_;
    std::size_t size_;
    TableContext ctx_;
    BoundaryGrid grid_;
    double t_scale_ = 0;

    bool record(std::uint32_t a, std::uint32_t b, std::uint64_t& off) const;
    std::uint64_t normal_code(std::uint64_t off) const;
};

}  // namespace lat
