#pragma once
// Culling segments from an entry point to the grid points of an exit face: a face's grid, and
// for a sphere the exit points whose segment from p can meet it (the cone from p around the
// sphere, row by row). Shared by rasterization and the candidate tables.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "lattice/boundary_grid.h"
#include "math/bounds.h"

namespace lat {

// The grid points of one face of the box, in rows v of points u.
struct FaceLayout {
    int axis, level, ua, va, nu, nv;      // nu, nv: points along u and v
    std::vector<std::uint8_t> mask;       // faces of each point
    std::vector<std::uint8_t> canonical;  // 1 where this face is the point's lowest face
    std::vector<std::uint32_t> ids;
};

FaceLayout layout_face(const BoundaryGrid& grid, int face);

struct PartSphere {
    Vec3 c;  // lattice units
    double r;
    std::uint32_t part;
};

// The face-grid rectangle that can hold exits of segments from p that meet the box b: the
// central projection of b's corners onto the face plane; the whole face when unbounded.
void projected_range(const Vec3& p, const Bounds3& b, const FaceLayout& f, int& u0, int& u1,
                     int& v0, int& v1);

// Row v of face f: the u-interval of exits q whose segment from p can meet the sphere s, i.e.
// q inside the cone from p around the sphere. Conservative (padded against rounding); false
// for an empty interval.
bool cone_row(const Vec3& p, const PartSphere& s, const FaceLayout& f, int v, double& ulo,
              double& uhi);

// Every canonical exit point of face fl inside the cone from p around the sphere ps: calls
// visit(k, q) with k the point's index in the face and q its lattice coordinates.
template <class Visit>
void for_each_exit_in_cone(const Vec3& p, const PartSphere& ps, const FaceLayout& fl, Visit&& visit) {
    int u0, u1, v0, v1;
    const Vec3 rr{ps.r, ps.r, ps.r};
    projected_range(p, {ps.c - rr, ps.c + rr}, fl, u0, u1, v0, v1);
    for (int v = v0; v <= v1; ++v) {
        double ulo, uhi;
        if (!cone_row(p, ps, fl, v, ulo, uhi)) continue;
        // Clamp in double first: the interval may be unbounded or huge.
        const int ub = static_cast<int>(std::ceil(std::max(ulo, double(u0))));
        const int ue = static_cast<int>(std::floor(std::min(uhi, double(u1))));
        for (int u = ub; u <= ue; ++u) {
            const std::size_t k = static_cast<std::size_t>(v * fl.nu + u);
            if (!fl.canonical[k]) continue;
            Vec3 q;
            q[static_cast<std::size_t>(fl.axis)] = fl.level;
            q[static_cast<std::size_t>(fl.ua)] = u;
            q[static_cast<std::size_t>(fl.va)] = v;
            visit(k, q);
        }
    }
}

}  // namespace lat
