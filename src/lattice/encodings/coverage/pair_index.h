#pragma once
// Where the coverage table keeps an ordered pair of boundary points (its slot), so that pairs
// that are neighbours in ray space are neighbours in memory. The smooth filter blends 5 pairs a
// ray whose entry and exit points are corners of one cell of the 4-D grid (u, v of the entry
// face, u, v of the exit face); indexed a * N + b, each of them was a cache miss of its own
// (moving the entry point by one jumps N pairs), twice: its occupancy and its record.
//
// Here the pairs are filed by face pair (F, G), and within it by their 4-D coordinates
// (u_a, v_a, u_b, v_b) in tiles of 4 x 4 x 4 x 4, each tile 256 consecutive slots in Morton
// order (so a 2 x 2 x 2 x 2 cell is 16 consecutive slots). A blend's pairs lie in one tile,
// or in two when its cell straddles a tile border along one coordinate (one in four along
// each).
//
// A point on an edge or corner lies on several faces; a pair is filed under one choice of
// faces only (filed_faces), so the slots are an injection of the valid pairs (different
// points, not both on a single face); the other slots, and those of the tiles' padding past
// a face's last point, stay empty.
#include <array>
#include <cstdint>
#include <vector>

#include "lattice/boundary_grid.h"

namespace lat {

class PairIndex {
public:
    static constexpr std::uint64_t kNone = ~std::uint64_t{0};
    static constexpr int kSide = 4;            // tile side along each coordinate
    static constexpr int kTileSlots = 256;     // kSide^4
    // 16 consecutive slots from a multiple of 16 are a 2 x 2 x 2 x 2 cell of the 4-D grid.
    static constexpr int kCellSlots = 16;

    // Cells positive, at most 0xFFFF boundary points (the coverage encoding's max_points).
    explicit PairIndex(const std::array<int, 3>& cells);

    const BoundaryGrid& grid() const { return grid_; }
    // Slots in all, a whole number of tiles.
    std::uint64_t slots() const { return tiles_ * kTileSlots; }

    // The pair's slot, or kNone when it is not a valid pair (a point out of range, a == b, or
    // both on a single face). The tile index is linear in the two points' tiles in their
    // faces and the Morton bits are theirs ORed, so it is a sum of per-point terms.
    std::uint64_t slot(std::uint32_t a, std::uint32_t b) const {
        if (a >= points_.size() || b >= points_.size() || a == b) return kNone;
        const Point& pa = points_[a];
        const Point& pb = points_[b];
        int f = 0, g = 0;
        if (!filed_faces(pa.faces, pb.faces, f, g)) return kNone;
        const std::uint32_t va = pa.at[f], vb = pb.at[g];
        return blocks_[f * 6 + g].first_tile * kTileSlots + std::uint64_t{va >> 8} * face_slots_[g] +
               (va & 0xFF) + std::uint64_t{vb >> 8} * kTileSlots + ((vb & 0xFF) << 2);
    }

    // The pair filed at slot s, or false when no valid pair is.
    bool pair_at(std::uint64_t s, std::uint32_t& a, std::uint32_t& b) const;
    // Whether a pair is filed in every slot of the tile whose bit is set (bit k: slot
    // tile * kTileSlots + k), for opening a table: quick for the slots inside their faces and
    // short of the padding (most of them), slot by slot only on the faces' edges.
    bool filed(std::uint64_t tile, const std::array<std::uint64_t, kTileSlots / 64>& slots) const;

    // The faces (f of a, g of b) a valid pair is filed under: a's lowest face and b's lowest
    // other than it, or, when b lies on that face alone, b's face and a's next one. False for
    // pairs on a single face (BoundaryGrid::valid_pair).
    static bool filed_faces(std::uint8_t fa, std::uint8_t fb, int& f, int& g) {
        f = __builtin_ctz(fa);
        if (const unsigned rest = fb & ~(1u << f)) {
            g = __builtin_ctz(rest);
            return true;
        }
        g = f;
        const unsigned other = fa & ~(1u << f);
        if (!other) return false;
        f = __builtin_ctz(other);
        return true;
    }

private:
    // A point's faces, and on each of them its tile in the face's grid of tiles (bits 8 up)
    // and its Morton bits as an entry point (bits 0, 1, 4, 5; as an exit point they are shifted
    // by 2): 28 bytes, so that the points of a lattice (at most 0xFFFF) mostly stay in cache.
    struct Point {
        std::uint32_t at[6];
        std::uint8_t faces;
    };
    // A face pair's tiles: the first one's index, their count along each coordinate, and the
    // coordinates' extents (points along the face axes).
    struct Block {
        std::uint64_t first_tile = 0;
        std::uint32_t tiles[4] = {0, 0, 0, 0};
        int extent[4] = {0, 0, 0, 0};
    };
    // Face f's u and v axes (as FilteredLatticeShape's blend takes them).
    static const int* face_axes(int f) { return kFaceAxes[BoundaryGrid::face_axis(f)]; }
    // Bits 0 and 1 of a coordinate within its tile, to bits 0 and 4 of its Morton code.
    static constexpr unsigned kSpread[4] = {0x00, 0x01, 0x10, 0x11};

    BoundaryGrid grid_;
    std::vector<Point> points_;
    Block blocks_[36];
    std::uint64_t face_slots_[6] = {0, 0, 0, 0, 0, 0};  // slots of a face's grid of tiles
    std::uint64_t tiles_ = 0;

    // The block and tile coordinates of a tile; false past the last tile.
    bool locate(std::uint64_t tile, int& block, std::uint32_t t[4]) const;
    // pair_at for a located tile and a slot in it.
    bool pair_in(int block, const std::uint32_t t[4], unsigned inner, std::uint32_t& a,
                 std::uint32_t& b) const;
    // Coordinate i (0 to 3) of a slot of the tile, from its Morton bits.
    static int coordinate(const std::uint32_t t[4], unsigned inner, int i) {
        return static_cast<int>(t[i]) * kSide + static_cast<int>(((inner >> i) & 1) | ((inner >> (i + 3)) & 2));
    }
};

}  // namespace lat
