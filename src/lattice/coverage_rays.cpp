#include "lattice/coverage_rays.h"

#include <algorithm>
#include <cmath>

namespace lat {
namespace {

// The axis of p's face that the direction d crosses most squarely.
std::size_t crossing_axis(const BoundaryGrid& grid, const GridPoint& p, const Vec3& d) {
    const std::uint8_t faces = grid.faces(p);
    std::size_t axis = 0;
    double best = -1;
    for (int f = 0; f < 6; ++f)
        if ((faces >> f) & 1) {
            const auto ax = static_cast<std::size_t>(BoundaryGrid::face_axis(f));
            if (std::abs(d[ax]) > best) best = std::abs(d[ax]), axis = ax;
        }
    return axis;
}

// Margins of guess_snap (lattice units). Snap computes a sub-ray's entry and exit from the ray
// (p h, (q - p) h) it is given, which puts them within ~1e-13 of p and q times the box's size
// over the direction's component across the face; with that component at least kMinCross and
// the box under 2,000 cells, that is far below kMargin, and the other faces' slab parameters
// (at least kMargin / 3,500 from the face's) keep snap on the same face.
constexpr double kMargin = 1e-6;
constexpr double kMinCross = 1e-2;
constexpr int kMaxCells = 2000;

// Whether x lies in (kMargin, n - kMargin) on the two axes other than `axis`.
bool inside_face(const Vec3& x, std::size_t axis, const std::array<int, 3>& n) {
    for (std::size_t k = 0; k < 3; ++k)
        if (k != axis && !(x[k] > kMargin && x[k] < n[k] - kMargin)) return false;
    return true;
}

}  // namespace

PairRays::PairRays(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q)
    : n_(grid.cells()), gq_(q), vp_(to_vec(p)), vq_(to_vec(q)), d_(vq_ - vp_),
      ap_(crossing_axis(grid, p, d_)), aq_(crossing_axis(grid, q, d_)) {}

double PairRays::reach() const {
    constexpr double kShift = 0.70710678118654757;  // sqrt(2) / 2, the longest shift
    // The exit moves by du U + dv V from q.
    double move = 0;
    for (std::size_t axis : {u_axis(), v_axis()}) {
        Vec3 u;
        u[axis] = 1;
        if (d_[aq_] != 0) u = u - d_ * (u[aq_] / d_[aq_]);
        move += 0.5 * length(u);
    }
    bool clamps = false;
    for (std::size_t k = 0; k < 3; ++k)
        clamps = clamps || (k != aq_ && (vq_[k] - move < 0 || vq_[k] + move > n_[k]));
    return clamps ? kShift + move : kShift;
}

// With s.p on p's face plane strictly inside the face, and the sub-ray crossing that plane
// inwards, snap's entry is that face (the other slabs' entries lie before it) and rounds to p
// (the shift is under 1/2 a cell on each axis). Likewise s.q, on q's face plane (up to
// rounding), strictly inside that face, is the exit, and rounds to the grid point nearest to it
// unless a coordinate lies within kMargin of a half. Where s.p or s.q was clamped onto the box,
// they lie on an edge, not strictly inside a face: kUnsure.
PairRays::Snap PairRays::guess_snap(const SubRay& s) const {
    if (std::max({n_[0], n_[1], n_[2]}) > kMaxCells) return Snap::kUnsure;
    const Vec3 d = s.q - s.p;
    if (!(std::abs(d[ap_]) >= kMinCross && std::abs(d[aq_]) >= kMinCross)) return Snap::kUnsure;
    if (!inside_face(s.p, ap_, n_)) return Snap::kUnsure;
    if (!inside_face(s.q, aq_, n_)) return Snap::kUnsure;
    if (!(std::abs(s.q[aq_] - vq_[aq_]) <= kMargin)) return Snap::kUnsure;  // not on q's plane
    for (std::size_t k = 0; k < 3; ++k)
        if (k != ap_ && !(std::abs(s.p[k] - vp_[k]) < 0.5 - kMargin)) return Snap::kUnsure;
    bool pair = true;
    for (std::size_t k = 0; k < 3; ++k) {
        if (k == aq_) continue;
        const double x = s.q[k], f = x - std::floor(x);
        if (std::abs(f - 0.5) <= kMargin) return Snap::kUnsure;
        pair = pair && std::nearbyint(x) == gq_[static_cast<int>(k)];
    }
    return pair ? Snap::kPair : Snap::kOther;
}

}  // namespace lat
