#pragma once
// The grid points on the faces of a lattice box [0, nx] x [0, ny] x [0, nz] (lattice units:
// one cell is sigma). Each distinct point gets a dense id; a point on an edge or corner lies on
// two or three faces and still has one id. Faces are numbered 0..5: x = 0, x = nx, y = 0,
// y = ny, z = 0, z = nz.
#include <array>
#include <cassert>
#include <cstdint>

#include "math/vec.h"

namespace lat {

struct GridPoint {
    int x = 0, y = 0, z = 0;
    int operator[](int a) const { return a == 0 ? x : (a == 1 ? y : z); }
    int& operator[](int a) { return a == 0 ? x : (a == 1 ? y : z); }
    bool operator==(const GridPoint&) const = default;
};

// The point in lattice units.
inline Vec3 to_vec(const GridPoint& g) {
    return {double(g.x), double(g.y), double(g.z)};
}

// Rounding a ray's entry or exit point to the nearest grid point on its face moves it by at
// most sqrt(2)/2 cells (two coordinates rounded by half a cell each), so every point of the
// snapped segment lies within this of the ray (lattice units, with slack for rounding).
inline constexpr double kSnapReach = 0.70711 + 1e-6;

// The two axes across axis a, in the order a face across it takes them as its u and v:
// x -> (y, z), y -> (z, x), z -> (x, y).
inline constexpr int kFaceAxes[3][2] = {{1, 2}, {2, 0}, {0, 1}};

class BoundaryGrid {
public:
    explicit BoundaryGrid(std::array<int, 3> cells);

    const std::array<int, 3>& cells() const { return n_; }
    std::uint32_t count() const { return count_; }

    // Id of a point on the boundary (at least one coordinate at 0 or n).
    std::uint32_t id(const GridPoint& p) const;
    GridPoint point(std::uint32_t id) const;
    // Bit f set when the point lies on face f.
    std::uint8_t faces(const GridPoint& p) const;

    static int face_axis(int face) { return face >> 1; }
    static bool face_is_high(int face) { return (face & 1) != 0; }
    // The face's plane coordinate along its axis.
    int face_level(int face) const { return face_is_high(face) ? n_[face_axis(face)] : 0; }
    // Points on face f: (n_u + 1) * (n_v + 1) with u, v its kFaceAxes.
    std::uint64_t face_points(int face) const;
    // Ordered pairs of face points on different faces, counted as the paper's eq. (2) does.
    std::uint64_t pairs_eq2() const;
    // The same for any cells, in floating point, so that absurd lattices cannot overflow it.
    static long double pair_count(const std::array<int, 3>& cells);
    // Whether ids of the lattice's boundary points fit in 32 bits (a grid can be built), for any
    // cells; positive cells assumed.
    static bool indexable(const std::array<int, 3>& cells);

    // A pair of boundary points can carry a ray through the lattice only if they are on
    // different faces: not both on the same single face.
    static bool valid_pair(std::uint8_t fa, std::uint8_t fb) {
        const std::uint8_t u = fa | fb;
        return (u & (u - 1)) != 0;
    }
    // How many (face of a, face of b) choices with different faces the pair stands for.
    static int multiplicity(std::uint8_t fa, std::uint8_t fb) {
        return __builtin_popcount(fa) * __builtin_popcount(fb) - __builtin_popcount(fa & fb);
    }

private:
    std::array<int, 3> n_;
    std::uint32_t full_ = 0;  // points in a full z layer, (nx+1)(ny+1)
    std::uint32_t ring_ = 0;  // points in an inner z layer, 2(nx+1) + 2(ny-1)
    std::uint32_t count_ = 0;
};

// Layout: the z = 0 layer in full, then the rings of the inner layers, then z = nz in full.
inline std::uint32_t BoundaryGrid::id(const GridPoint& p) const {
    const auto nx = static_cast<std::uint32_t>(n_[0]), ny = static_cast<std::uint32_t>(n_[1]);
    const auto x = static_cast<std::uint32_t>(p.x), y = static_cast<std::uint32_t>(p.y);
    if (p.z == 0) return y * (nx + 1) + x;
    if (p.z == n_[2])
        return full_ + static_cast<std::uint32_t>(n_[2] - 1) * ring_ + y * (nx + 1) + x;
    const std::uint32_t base = full_ + static_cast<std::uint32_t>(p.z - 1) * ring_;
    if (y == 0) return base + x;
    if (y == ny) return base + (nx + 1) + x;
    assert(x == 0 || x == nx);
    return base + 2 * (nx + 1) + 2 * (y - 1) + (x == 0 ? 0 : 1);
}

}  // namespace lat
