#pragma once
// Culling segments from an entry point to the grid points of an exit face: a face's grid, and
// for a sphere the exit points whose segment from p can meet it (the cone from p around the
// sphere, row by row). Shared by rasterization and the candidate tables.
#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "geometry/shape.h"
#include "lattice/boundary_grid.h"
#include "math/bounds.h"

namespace lat {

// The grid points of one face of the box, in rows v of points u.
struct FaceLayout {
    int axis, level, ua, va, nu, nv;      // nu, nv: points along u and v
    std::vector<std::uint8_t> mask;       // faces of each point
    std::vector<std::uint8_t> canonical;  // 1 where this face is the point's lowest face
    std::vector<std::uint32_t> ids;
    // Row v's canonical points are u in [canon_u0[v], canon_u1[v]] (none when u0 > u1): only the
    // box's edges are shared with other faces, so they are one run.
    std::vector<int> canon_u0, canon_u1;
};

FaceLayout layout_face(const BoundaryGrid& grid, int face);

struct PartSphere {
    Vec3 c;  // lattice units
    double r;
    std::uint32_t part;
};

// Sphere b (lattice units) of part `part` grown by `grow` cells and padded against rounding by
// `rel_pad` of the radius and 1e-9.
inline PartSphere grown_sphere(const BoundingSphere& b, std::uint32_t part, double grow,
                               double rel_pad) {
    return {b.center, (b.radius + grow) * (1 + rel_pad) + 1e-9, part};
}

// The culling spheres of every part of `shape` (Parts::part_spheres), in lattice units
// (cell: the primitive units of one), grown by `grow` cells and padded against rounding by
// `rel_pad` of the radius and 1e-9; grouped by part in ascending order, so a list built from
// them is sorted by part.
std::vector<PartSphere> part_spheres(const Shape& shape, double cell, double grow, double rel_pad);
// The same for the pieces of `shape` (Pieces::piece_spheres; a CSG tree's leaves), numbered by
// piece. Segments lie in the box (cells: its size in cells), so a sphere larger than the box's
// own (a half-space's unbounded one) is replaced by that: near every segment.
std::vector<PartSphere> piece_spheres(const Shape& shape, double cell, const Vec3& cells,
                                      double grow, double rel_pad);

// The face-grid rectangle that can hold exits of segments from p that meet the box b: the
// central projection of b's corners onto the face plane; the whole face when unbounded.
void projected_range(const Vec3& p, const Bounds3& b, const FaceLayout& f, int& u0, int& u1,
                     int& v0, int& v1);

// The rows of face f that can hold exits of segments from p that meet the sphere s: [v0, v1]
// less [g0, g1] (no rows when g0 > g1), false when none. A superset of the rows where
// ConeRows::row finds an interval (padded far beyond its rounding), found without visiting them:
// a sphere wholly behind p's plane parallel to the face is never met on the way to it, and a
// sphere wholly in front of it casts an ellipse, whose rows lie between the roots of a quadratic.
// A sphere that straddles that plane gets every row but those between the same quadratic's
// roots (g0 to g1), where it is negative. The one exit it may drop is p itself (p on the face,
// the sphere off its plane).
bool cone_rows(const Vec3& p, const PartSphere& s, const FaceLayout& f, int& v0, int& v1, int& g0,
               int& g1);

// The cone from p around the sphere s, cut by the rows of face f: row(v) is the u-interval of
// exits q whose segment from p can meet the sphere, i.e. q inside the cone. Conservative
// (padded against rounding); false for an empty interval. What does not depend on the row is
// worked out once (the same operations on the same values: the same intervals).
// (Inline: the rasterizer's hottest culling step.)
class ConeRows {
public:
    ConeRows(const Vec3& p, const PartSphere& s, const FaceLayout& f) {
        const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
                   va = static_cast<std::size_t>(f.va);
        const Vec3 w = s.c - p;
        pu_ = p[ua], pv_ = p[va], wv_ = w[va];
        k_ = length_squared(w) - s.r * s.r;
        da_ = f.level - p[ax];
        alpha0_ = da_ * w[ax];
        beta_ = w[ua];
        da2_ = da_ * da_;
        A_ = beta_ * beta_ - k_;
        whole_ = k_ <= 0 || A_ >= 0;  // p inside the sphere, or the cone opens along u
    }
    bool row(int v, double& ulo, double& uhi) const {
        if (whole_) {
            ulo = -kInfinity, uhi = kInfinity;
            return true;
        }
        const double dv = v - pv_;
        const double alpha = alpha0_ + dv * wv_;
        const double gamma = da2_ + dv * dv;
        // g(u') = (alpha + beta u')^2 - k (gamma + u'^2) >= 0 with alpha + beta u' >= 0, u' = u - p_u.
        const double B = alpha * beta_, C = alpha * alpha - k_ * gamma;
        const double disc = B * B - A_ * C;
        if (disc < 0) return false;
        const double sq = std::sqrt(disc);
        // r0 <= r1 since A < 0; both divisions in one instruction (the same values).
        const __m128d roots = _mm_div_pd(_mm_set_pd(-B - sq, -B + sq), _mm_set1_pd(A_));
        const double r0 = _mm_cvtsd_f64(roots), r1 = _mm_cvtsd_f64(_mm_unpackhi_pd(roots, roots));
        if (alpha + beta_ * 0.5 * (r0 + r1) < 0) return false;  // the cone's far nappe
        const double pad = 1e-7 * (1 + std::abs(r0) + std::abs(r1));
        ulo = pu_ + r0 - pad;
        uhi = pu_ + r1 + pad;
        return true;
    }

private:
    double pu_, pv_, wv_;  // p's coordinates along the face's u and v, and w = c - p's along v
    double k_, da_, alpha0_, beta_, da2_, A_;
    bool whole_;
};

// Every row of face fl that the cone from p around the sphere ps reaches, with the u-range of
// its canonical exits there (clamped to them and to the sphere's projection):
// visit_row(v, ub, ue) with ub <= ue, rows in ascending order.
template <class VisitRow>
void for_each_cone_row(const Vec3& p, const PartSphere& ps, const FaceLayout& fl, VisitRow&& visit_row) {
    int u0, u1, v0, v1, c0, c1, g0, g1;
    if (!cone_rows(p, ps, fl, c0, c1, g0, g1)) return;
    const Vec3 rr{ps.r, ps.r, ps.r};
    projected_range(p, {ps.c - rr, ps.c + rr}, fl, u0, u1, v0, v1);
    v0 = std::max(v0, c0), v1 = std::min(v1, c1);
    const ConeRows cone(p, ps, fl);
    // One loop that jumps the gap (two would not be inlined).
    if (g0 > g1) g0 = v1 + 1;
    if (g0 <= v0) v0 = std::max(v0, g1 + 1);
    for (int v = v0; v <= v1; ++v) {
        if (v == g0) {
            v = g1;
            continue;
        }
        double ulo, uhi;
        if (!cone.row(v, ulo, uhi)) continue;
        // Clamp in double first: the interval may be unbounded or huge.
        const int ub = std::max(static_cast<int>(std::ceil(std::max(ulo, double(u0)))),
                                fl.canon_u0[static_cast<std::size_t>(v)]);
        const int ue = std::min(static_cast<int>(std::floor(std::min(uhi, double(u1)))),
                                fl.canon_u1[static_cast<std::size_t>(v)]);
        if (ub <= ue) visit_row(v, ub, ue);
    }
}

// Every canonical exit point of face fl inside the cone from p around the sphere ps: calls
// visit(k, q) with k the point's index in the face and q its lattice coordinates.
template <class Visit>
void for_each_exit_in_cone(const Vec3& p, const PartSphere& ps, const FaceLayout& fl, Visit&& visit) {
    // q = base + u eu + v ev, exactly (small integers and zeros): writing q's coordinates by
    // runtime axis index instead stalls the load of q that follows on store forwarding.
    Vec3 base{0, 0, 0}, eu{0, 0, 0}, ev{0, 0, 0};
    base[static_cast<std::size_t>(fl.axis)] = fl.level;
    eu[static_cast<std::size_t>(fl.ua)] = 1;
    ev[static_cast<std::size_t>(fl.va)] = 1;
    for_each_cone_row(p, ps, fl, [&](int v, int ub, int ue) {
        const Vec3 row = base + ev * double(v);
        for (int u = ub; u <= ue; ++u)
            visit(static_cast<std::size_t>(v * fl.nu + u), row + eu * double(u));
    });
}

}  // namespace lat
