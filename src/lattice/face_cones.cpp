#include "lattice/face_cones.h"

#include <algorithm>
#include <cmath>

namespace lat {

FaceLayout layout_face(const BoundaryGrid& grid, int f) {
    FaceLayout fl;
    fl.axis = BoundaryGrid::face_axis(f);
    fl.level = grid.face_level(f);
    fl.ua = (fl.axis + 1) % 3;
    fl.va = (fl.axis + 2) % 3;
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
    return fl;
}

void projected_range(const Vec3& p, const Bounds3& b, const FaceLayout& f, int& u0, int& u1,
                     int& v0, int& v1) {
    u0 = 0, u1 = f.nu - 1, v0 = 0, v1 = f.nv - 1;
    const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
               va = static_cast<std::size_t>(f.va);
    const double num = f.level - p[ax];
    if (num == 0) return;
    double umin = kInfinity, umax = -kInfinity, vmin = kInfinity, vmax = -kInfinity;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c = b.corner(k);
        const double den = c[ax] - p[ax];
        if (den * num <= 0) return;
        const double s = num / den;
        const double u = p[ua] + s * (c[ua] - p[ua]), v = p[va] + s * (c[va] - p[va]);
        umin = std::min(umin, u), umax = std::max(umax, u);
        vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    }
    const double eps = 1e-9;
    u0 = static_cast<int>(std::ceil(std::max(umin - eps, double(u0))));
    u1 = static_cast<int>(std::floor(std::min(umax + eps, double(u1))));
    v0 = static_cast<int>(std::ceil(std::max(vmin - eps, double(v0))));
    v1 = static_cast<int>(std::floor(std::min(vmax + eps, double(v1))));
}

bool cone_row(const Vec3& p, const PartSphere& s, const FaceLayout& f, int v, double& ulo,
              double& uhi) {
    const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
               va = static_cast<std::size_t>(f.va);
    const Vec3 w = s.c - p;
    const double k = length_squared(w) - s.r * s.r;
    const double da = f.level - p[ax], dv = v - p[va];
    const double alpha = da * w[ax] + dv * w[va], beta = w[ua];
    const double gamma = da * da + dv * dv;
    // g(u') = (alpha + beta u')^2 - k (gamma + u'^2) >= 0 with alpha + beta u' >= 0, u' = u - p_u.
    const double A = beta * beta - k, B = alpha * beta, C = alpha * alpha - k * gamma;
    if (k <= 0 || A >= 0) {  // p inside the sphere, or the cone opens along u: the whole row
        ulo = -kInfinity, uhi = kInfinity;
        return true;
    }
    const double disc = B * B - A * C;
    if (disc < 0) return false;
    const double sq = std::sqrt(disc);
    const double r0 = (-B + sq) / A, r1 = (-B - sq) / A;   // r0 <= r1 since A < 0
    if (alpha + beta * 0.5 * (r0 + r1) < 0) return false;  // the cone's far nappe
    const double pad = 1e-7 * (1 + std::abs(r0) + std::abs(r1));
    ulo = p[ua] + r0 - pad;
    uhi = p[ua] + r1 + pad;
    return true;
}

}  // namespace lat
