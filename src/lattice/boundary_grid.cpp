#include "lattice/boundary_grid.h"

#include <cassert>

namespace lat {

BoundaryGrid::BoundaryGrid(std::array<int, 3> cells) : n_(cells) {
    assert(n_[0] >= 1 && n_[1] >= 1 && n_[2] >= 1);
    full_ = static_cast<std::uint32_t>((n_[0] + 1) * (n_[1] + 1));
    ring_ = static_cast<std::uint32_t>(2 * (n_[0] + 1) + 2 * (n_[1] - 1));
    count_ = 2 * full_ + static_cast<std::uint32_t>(n_[2] - 1) * ring_;
}

GridPoint BoundaryGrid::point(std::uint32_t id) const {
    const auto nx = static_cast<std::uint32_t>(n_[0]), ny = static_cast<std::uint32_t>(n_[1]);
    if (id < full_) return {static_cast<int>(id % (nx + 1)), static_cast<int>(id / (nx + 1)), 0};
    id -= full_;
    const std::uint32_t inner = static_cast<std::uint32_t>(n_[2] - 1) * ring_;
    if (id >= inner) {
        id -= inner;
        return {static_cast<int>(id % (nx + 1)), static_cast<int>(id / (nx + 1)), n_[2]};
    }
    const int z = static_cast<int>(id / ring_) + 1;
    std::uint32_t r = id % ring_;
    if (r < nx + 1) return {static_cast<int>(r), 0, z};
    r -= nx + 1;
    if (r < nx + 1) return {static_cast<int>(r), static_cast<int>(ny), z};
    r -= nx + 1;
    return {(r & 1) ? static_cast<int>(nx) : 0, static_cast<int>(r / 2 + 1), z};
}

std::uint8_t BoundaryGrid::faces(const GridPoint& p) const {
    std::uint8_t m = 0;
    for (int a = 0; a < 3; ++a) {
        if (p[a] == 0) m |= static_cast<std::uint8_t>(1u << (2 * a));
        if (p[a] == n_[static_cast<std::size_t>(a)]) m |= static_cast<std::uint8_t>(1u << (2 * a + 1));
    }
    return m;
}

std::uint64_t BoundaryGrid::face_points(int face) const {
    const int a = face_axis(face);
    return static_cast<std::uint64_t>(n_[static_cast<std::size_t>(kFaceAxes[a][0])] + 1) *
           static_cast<std::uint64_t>(n_[static_cast<std::size_t>(kFaceAxes[a][1])] + 1);
}

std::uint64_t BoundaryGrid::pairs_eq2() const {
    // Paper eq. (2): 8 (xy yz + yz zx + zx xy) + 2 (xy² + yz² + zx²) = S² - sum of N_f².
    const std::uint64_t yz = face_points(0), zx = face_points(2), xy = face_points(4);
    return 8 * (xy * yz + yz * zx + zx * xy) + 2 * (xy * xy + yz * yz + zx * zx);
}

bool BoundaryGrid::indexable(const std::array<int, 3>& cells) {
    const long double nx = cells[0], ny = cells[1], nz = cells[2];
    // An upper bound on the points (edges counted twice), in floating point: no overflow.
    return 2 * ((nx + 1) * (ny + 1) + (ny + 1) * (nz + 1) + (nz + 1) * (nx + 1)) <
           static_cast<long double>(0xFFFFFFFFu);
}

long double BoundaryGrid::pair_count(const std::array<int, 3>& cells) {
    const long double nx = cells[0], ny = cells[1], nz = cells[2];
    const long double yz = (ny + 1) * (nz + 1), zx = (nz + 1) * (nx + 1), xy = (nx + 1) * (ny + 1);
    return 8 * (xy * yz + yz * zx + zx * xy) + 2 * (xy * xy + yz * yz + zx * zx);
}

}  // namespace lat
