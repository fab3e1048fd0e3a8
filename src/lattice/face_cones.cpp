#include "lattice/face_cones.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "geometry/lattice_source.h"

namespace lat {

FaceLayout layout_face(const BoundaryGrid& grid, int f) {
    FaceLayout fl;
    fl.axis = BoundaryGrid::face_axis(f);
    fl.level = grid.face_level(f);
    fl.ua = kFaceAxes[fl.axis][0];
    fl.va = kFaceAxes[fl.axis][1];
    fl.nu = grid.cells()[static_cast<std::size_t>(fl.ua)] + 1;
    fl.nv = grid.cells()[static_cast<std::size_t>(fl.va)] + 1;
    const std::size_t n = static_cast<std::size_t>(fl.nu) * static_cast<std::size_t>(fl.nv);
    fl.mask.resize(n), fl.canonical.resize(n), fl.ids.resize(n);
    for (int v = 0; v < fl.nv; ++v)
        for (int u = 0; u < fl.nu; ++u) {
            GridPoint q;
            q[fl.axis] = fl.level, q[fl.ua] = u, q[fl.va] = v;
            const std::size_t k = static_cast<std::size_t>(v * fl.nu + u);
            fl.mask[k] = grid.faces(q);
            fl.canonical[k] = (__builtin_ctz(fl.mask[k]) == f) ? 1 : 0;
            fl.ids[k] = grid.id(q);
        }
    fl.canon_u0.assign(static_cast<std::size_t>(fl.nv), 0);
    fl.canon_u1.assign(static_cast<std::size_t>(fl.nv), -1);
    for (int v = 0; v < fl.nv; ++v) {
        const std::uint8_t* row = &fl.canonical[static_cast<std::size_t>(v * fl.nu)];
        int u0 = 0, u1 = fl.nu - 1;
        while (u0 < fl.nu && !row[u0]) ++u0;
        while (u1 >= u0 && !row[u1]) --u1;
        for (int u = u0; u <= u1; ++u) assert(row[u] && "a face row's canonical points are one run");
        if (u0 <= u1) fl.canon_u0[static_cast<std::size_t>(v)] = u0, fl.canon_u1[static_cast<std::size_t>(v)] = u1;
    }
    return fl;
}

void projected_range(const Vec3& p, const Bounds3& b, const FaceLayout& f, int& u0, int& u1,
                     int& v0, int& v1) {
    u0 = 0, u1 = f.nu - 1, v0 = 0, v1 = f.nv - 1;
    const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
               va = static_cast<std::size_t>(f.va);
    const double num = f.level - p[ax];
    if (num == 0) return;
    // A corner's projection along u (v) depends on its coordinates along the face's axis and
    // u (v) alone: the eight corners give two scales and four values each way.
    const double den[2] = {b.lo[ax] - p[ax], b.hi[ax] - p[ax]};
    if (den[0] * num <= 0 || den[1] * num <= 0) return;
    double umin = kInfinity, umax = -kInfinity, vmin = kInfinity, vmax = -kInfinity;
    for (const double d : den) {
        const double s = num / d;
        for (const double cu : {b.lo[ua], b.hi[ua]}) {
            const double u = p[ua] + s * (cu - p[ua]);
            umin = std::min(umin, u), umax = std::max(umax, u);
        }
        for (const double cv : {b.lo[va], b.hi[va]}) {
            const double v = p[va] + s * (cv - p[va]);
            vmin = std::min(vmin, v), vmax = std::max(vmax, v);
        }
    }
    const double eps = 1e-9;
    u0 = static_cast<int>(std::ceil(std::max(umin - eps, double(u0))));
    u1 = static_cast<int>(std::floor(std::min(umax + eps, double(u1))));
    v0 = static_cast<int>(std::ceil(std::max(vmin - eps, double(v0))));
    v1 = static_cast<int>(std::floor(std::min(vmax + eps, double(v1))));
}

bool cone_rows(const Vec3& p, const PartSphere& s, const FaceLayout& f, int& v0, int& v1, int& g0,
               int& g1) {
    v0 = 0, v1 = f.nv - 1;
    g0 = 0, g1 = -1;
    const auto ax = static_cast<std::size_t>(f.axis), va = static_cast<std::size_t>(f.va);
    const double da = f.level - p[ax];
    const double wax = s.c[ax] - p[ax], wva = s.c[va] - p[va];
    const double margin = 1e-6 * (s.r + std::abs(wax) + std::abs(wva)) + 1e-9;
    // p in the face's plane: segments in that plane meet only a sphere that reaches it (else
    // ConeRows finds p itself alone, which pairs with nothing).
    if (da == 0) return std::abs(wax) <= s.r + margin;
    const double ahead = da > 0 ? wax : -wax;  // how far the centre lies towards the face
    if (ahead + s.r < -margin) return false;    // wholly behind
    // Exits at row offset dv = v - p_v meet the cone where
    // (r^2 - wax^2) dv^2 + 2 da wax wva dv + (r^2 - wva^2) da^2 >= 0 (the row's discriminant
    // in ConeRows::row over |w|^2 - r^2); with |wax| > r the leading coefficient is negative.
    const double a2 = s.r * s.r - wax * wax;
    if (ahead - s.r <= margin) {
        // Straddles: every row but those strictly between the roots (a2 > 0 clearly), where
        // the quadratic is negative (most rows of such a sphere).
        const double q = wax * wax + wva * wva - s.r * s.r;
        if (!(a2 > 0.01 * s.r * s.r) || !(q > 0)) return true;
        const double h = std::abs(da) * s.r * std::sqrt(q);
        const double b = -da * wax * wva;
        const double r0 = (b - h) / a2, r1 = (b + h) / a2;  // r0 <= r1 since a2 > 0
        const double pad = 1e-6 * (1 + std::abs(r0) + std::abs(r1) + std::abs(da));
        const double lo = p[va] + r0 + pad, hi = p[va] + r1 - pad;
        // Clamp in double first: the roots may lie far off the face.
        if (!(lo < hi) || !(hi > v0) || !(lo < v1)) return true;
        g0 = static_cast<int>(std::floor(std::max(lo, double(v0) - 1))) + 1;
        g1 = static_cast<int>(std::ceil(std::min(hi, double(v1) + 1))) - 1;
        return true;
    }
    const double h = std::abs(da) * s.r * std::sqrt(wax * wax + wva * wva - s.r * s.r);
    const double b = -da * wax * wva;
    const double r0 = (b + h) / a2, r1 = (b - h) / a2;  // r0 <= r1 since a2 < 0
    const double pad = 1e-6 * (1 + std::abs(r0) + std::abs(r1) + std::abs(da));
    const double lo = p[va] + r0 - pad, hi = p[va] + r1 + pad;
    // Clamp in double first: the rows may lie far off the face.
    if (!(lo <= v1) || !(hi >= v0)) return false;
    v0 = static_cast<int>(std::ceil(std::max(lo, double(v0))));
    v1 = static_cast<int>(std::floor(std::min(hi, double(v1))));
    return v0 <= v1;
}

std::vector<PartSphere> part_spheres(const Shape& s, double cell, double grow, double rel_pad) {
    const ShapeParts shape(s);
    std::vector<PartSphere> out;
    std::vector<BoundingSphere> bs;
    for (std::size_t i = 0; i < shape.part_count(); ++i) {
        bs.clear();
        shape.part_spheres(i, bs);
        for (const BoundingSphere& b : bs)
            out.push_back(grown_sphere({b.center / cell, b.radius / cell},
                                       static_cast<std::uint32_t>(i), grow, rel_pad));
    }
    return out;
}

std::vector<PartSphere> piece_spheres(const Shape& s, double cell, const Vec3& cells,
                                      double grow, double rel_pad) {
    const ShapeSource shape(s);
    const BoundingSphere box{cells * 0.5, 0.5 * length(cells)};
    std::vector<PartSphere> out;
    std::vector<BoundingSphere> bs;
    for (std::size_t i = 0; i < shape.piece_count(); ++i) {
        bs.clear();
        shape.piece_spheres(i, bs);
        for (BoundingSphere b : bs) {
            b = {b.center / cell, b.radius / cell};
            if (!(b.radius < box.radius) || !std::isfinite(length_squared(b.center))) b = box;
            out.push_back(grown_sphere(b, static_cast<std::uint32_t>(i), grow, rel_pad));
        }
    }
    return out;
}

}  // namespace lat
