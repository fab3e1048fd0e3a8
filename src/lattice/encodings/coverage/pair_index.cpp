#include "lattice/encodings/coverage/pair_index.h"

#include <bit>
#include <cassert>

namespace lat {

PairIndex::PairIndex(const std::array<int, 3>& cells) : grid_(cells) {
    assert(grid_.count() <= 0xFFFFu);
    // A face's grid of tiles: tiles along u times along v, as the blocks take them.
    std::uint32_t tiles_v[6] = {0, 0, 0, 0, 0, 0};
    for (int f = 0; f < 6; ++f) {
        const auto side = [&](int j) {
            return static_cast<std::uint32_t>((cells[static_cast<std::size_t>(face_axes(f)[j])] + kSide) / kSide);
        };
        tiles_v[f] = side(1);
        face_slots_[f] = std::uint64_t{side(0)} * side(1) * kTileSlots;
    }
    points_.resize(grid_.count());
    for (std::uint32_t id = 0; id < grid_.count(); ++id) {
        const GridPoint p = grid_.point(id);
        Point& q = points_[id];
        q.faces = grid_.faces(p);
        for (int f = 0; f < 6; ++f) {
            const int u = p[face_axes(f)[0]], v = p[face_axes(f)[1]];
            const std::uint32_t tile = static_cast<std::uint32_t>(u / kSide) * tiles_v[f] +
                                       static_cast<std::uint32_t>(v / kSide);
            q.at[f] = tile << 8 | kSpread[u % kSide] | kSpread[v % kSide] << 1;
        }
    }
    for (int f = 0; f < 6; ++f)
        for (int g = 0; g < 6; ++g) {
            Block& k = blocks_[f * 6 + g];
            k.first_tile = tiles_;
            if (f == g) continue;  // no pair is filed on one face: an empty block
            std::uint64_t n = 1;
            for (int i = 0; i < 4; ++i) {
                const int face = i < 2 ? f : g;
                k.extent[i] = cells[static_cast<std::size_t>(face_axes(face)[i % 2])] + 1;
                k.tiles[i] = static_cast<std::uint32_t>((k.extent[i] + kSide - 1) / kSide);
                n *= k.tiles[i];
            }
            tiles_ += n;
        }
}

bool PairIndex::locate(std::uint64_t tile, int& block, std::uint32_t t[4]) const {
    if (tile >= tiles_) return false;
    // The last block starting at or before the tile (the empty ones start where the next does).
    block = 35;
    while (blocks_[block].first_tile > tile || blocks_[block].tiles[0] == 0) --block;
    std::uint64_t r = tile - blocks_[block].first_tile;
    for (int i = 3; i >= 0; --i) {
        t[i] = static_cast<std::uint32_t>(r % blocks_[block].tiles[i]);
        r /= blocks_[block].tiles[i];
    }
    return true;
}

bool PairIndex::pair_at(std::uint64_t s, std::uint32_t& a, std::uint32_t& b) const {
    int block = 0;
    std::uint32_t t[4];
    return locate(s / kTileSlots, block, t) &&
           pair_in(block, t, static_cast<unsigned>(s % kTileSlots), a, b);
}

bool PairIndex::pair_in(int block, const std::uint32_t t[4], unsigned inner, std::uint32_t& a,
                        std::uint32_t& b) const {
    const Block& k = blocks_[block];
    const int f = block / 6, g = block % 6;
    GridPoint p[2];
    for (int i = 0; i < 4; ++i) {
        const int c = coordinate(t, inner, i);
        if (c >= k.extent[i]) return false;  // the tile's padding
        const int face = i < 2 ? f : g;
        p[i / 2][face_axes(face)[i % 2]] = c;
    }
    for (int e = 0; e < 2; ++e) {
        const int face = e == 0 ? f : g;
        p[e][BoundaryGrid::face_axis(face)] = grid_.face_level(face);
    }
    a = grid_.id(p[0]);
    b = grid_.id(p[1]);
    int ff = 0, gg = 0;
    return a != b && filed_faces(grid_.faces(p[0]), grid_.faces(p[1]), ff, gg) && ff == f && gg == g;
}

bool PairIndex::filed(std::uint64_t tile, const std::array<std::uint64_t, kTileSlots / 64>& slots) const {
    int block = 0;
    std::uint32_t t[4];
    if (!locate(tile, block, t)) return false;
    // A slot whose coordinates are all 1 to extent - 2 holds points inside their faces, filed
    // under them (no other choice), short of the padding.
    bool inner_only = true;
    for (int i = 0; i < 4; ++i)
        inner_only = inner_only && t[i] > 0 && coordinate(t, 0xFF, i) < blocks_[block].extent[i] - 1;
    if (inner_only) return true;
    for (unsigned w = 0; w < slots.size(); ++w)
        for (std::uint64_t bits = slots[w]; bits; bits &= bits - 1) {
            const unsigned inner = w * 64 + static_cast<unsigned>(std::countr_zero(bits));
            bool inside = true;
            for (int i = 0; i < 4; ++i) {
                const int c = coordinate(t, inner, i);
                inside = inside && c > 0 && c < blocks_[block].extent[i] - 1;
            }
            std::uint32_t a = 0, b = 0;
            if (!inside && !pair_in(block, t, inner, a, b)) return false;
        }
    return true;
}

}  // namespace lat
