#include "geometry/algebraic.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "geometry/quartic_solver.h"

namespace lat {
namespace {

double sqr(double x) { return x * x; }

double horner(const double g[5], double u) {
    return (((g[4] * u + g[3]) * u + g[2]) * u + g[1]) * u + g[0];
}

}  // namespace

AlgebraicShape::AlgebraicShape(const Poly3& f, const Bounds3& bounds, Vec3 center)
    : f_(f), bounds_(bounds), center_(center), degree_(f.degree()) {}

AlgebraicShape::AlgebraicShape(const Poly3& f, const Bounds3& bounds, Vec3 center,
                               RingExtent extent)
    : AlgebraicShape(f, bounds, center) {
    has_extent_ = true;
    extent_ = extent;
}

// The solid lies in circle + ball, so its image under x -> M x + t lies in M circle + M ball,
// whose support along world axis k is the sum of theirs: with m the k-th row of M,
// ring |m projected onto the z = 0 plane| + ball |m|. (A torus of major radius R, minor r
// about unit axis n under a rotation: R sqrt(1 - n_k^2) + r, its exact extent.)
Bounds3 AlgebraicShape::placed_bounds(const Transform& xf) const {
    if (!has_extent_) return Shape::placed_bounds(xf);
    const Affine& a = xf.forward();
    Vec3 e;
    for (std::size_t k = 0; k < 3; ++k) {
        const Vec3& m = a.m.r[k];
        e[k] = extent_.ring * std::sqrt(m.x * m.x + m.y * m.y) + extent_.ball * length(m);
    }
    const Vec3 c = xf.point({0, 0, 0});
    return lat::intersect({c - e, c + e}, Shape::placed_bounds(xf));
}

// Every circle point lies within pi/n of the angle of one of n equally spaced centres, so within
// the chord 2 ring sin(pi / 2n) of it; n ~ 3 pi ring / ball keeps that chord near a third of the
// ball (at most 128 spheres): candidate lists of the CSG of tori then leave out 8 % more leaves
// than with a chord near the ball.
bool AlgebraicShape::bounding_spheres(std::vector<BoundingSphere>& out) const {
    if (!has_extent_) return false;
    if (extent_.ring <= 0) {
        out.push_back({{0, 0, 0}, extent_.ball});
        return true;
    }
    const double want = std::ceil(3 * std::numbers::pi * extent_.ring / extent_.ball);  // or inf
    const int n = static_cast<int>(std::clamp(want, 3.0, 128.0));
    const double chord = 2 * extent_.ring * std::sin(std::numbers::pi / (2 * n));
    const double r = (extent_.ball + chord) * (1 + 1e-12);
    for (int k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * k / n;
        out.push_back({{extent_.ring * std::cos(a), extent_.ring * std::sin(a), 0}, r});
    }
    return true;
}

// The solid lies within `ball` of the ring: in the slab |z| <= ball and, there, at a distance
// from the z axis within ring +- ball. The line p + u dn (u in [u0, u1], the part in the box)
// crosses the slab in an interval where the squared axis distance is a convex quadratic in u,
// so its range there is known from the ends and the vertex. A torus's box holds its hole and
// the corners around it: on the CSG of six tori, two in five lines that met a torus's box missed
// this region and cost no quartic. Padded like the box, so no root of the solid is lost.
bool AlgebraicShape::misses_ring(Vec3 p, Vec3 dn, double u0, double u1) const {
    if (!has_extent_ || extent_.ring <= 0 || !bounds_.finite()) return false;
    const double pad = 1e-9 * max_component(bounds_.extent());
    const double ball = extent_.ball + pad;
    if (dn.z != 0) {
        double a = (-ball - p.z) / dn.z, b = (ball - p.z) / dn.z;
        if (a > b) std::swap(a, b);
        u0 = std::max(u0, a), u1 = std::min(u1, b);
        if (!(u0 <= u1)) return true;
    } else if (std::abs(p.z) > ball) {
        return true;
    }
    auto axis2 = [&](double u) { return sqr(p.x + u * dn.x) + sqr(p.y + u * dn.y); };
    const double a = sqr(dn.x) + sqr(dn.y), b = p.x * dn.x + p.y * dn.y;
    const double far2 = std::max(axis2(u0), axis2(u1));
    const double near2 = a > 0 ? axis2(std::clamp(-b / a, u0, u1)) : axis2(u0);
    const double inner = extent_.ring - ball, outer = extent_.ring + ball;
    return near2 > outer * outer || (inner > 0 && far2 < inner * inner);
}

bool AlgebraicShape::line_roots(const Ray& r, LineRoots& out) const {
    out.count = 0;
    const double len = length(r.d);
    if (len == 0.0 || degree_ <= 0) return false;
    const Vec3 dn = r.d / len;
    double tb0 = -kInfinity, tb1 = kInfinity;
    Vec3 c = center_;
    if (bounds_.finite()) {
        // Roots outside a bounded surface's box are rounding noise; the box also gives a centre.
        const Bounds3 padded = expand(bounds_, 1e-9 * max_component(bounds_.extent()));
        if (!clip_ray(padded, {r.o, dn}, tb0, tb1)) return false;
        c = bounds_.center();
    }
    // Solve in u, the distance along the unit direction from the point nearest the centre.
    const double shift = dot(c - r.o, dn);
    const Vec3 near_c = r.o + dn * shift;
    if (misses_ring(near_c, dn, tb0 - shift, tb1 - shift)) return false;
    f_.along_ray(near_c, dn, out.g);
    // Extreme coefficients or a far-away ray can overflow the restriction; no root is then
    // trustworthy, and the solver must not see infinities.
    for (const double gi : out.g)
        if (!std::isfinite(gi)) return false;
    double u[4];
    int n = 0;
    if (degree_ <= 2) {
        n = solve_quadratic(out.g, u);
    } else {
        n = solve_quartic(out.g, u);
    }
    out.shift = shift;
    out.scale = 1.0 / len;
    for (int i = 0; i < n; ++i) {
        const double s = shift + u[i];
        if (s < tb0 || s > tb1) continue;
        out.t[out.count++] = s / len;
    }
    return out.count > 0;
}

bool AlgebraicShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    LineRoots lr;
    if (!line_roots(r, lr)) return false;
    for (int i = 0; i < lr.count; ++i) {
        if (lr.t[i] > tmin && lr.t[i] < tmax) {
            hit = {lr.t[i], 0, 0};
            return true;
        }
    }
    return false;
}

void AlgebraicShape::spans(const Ray& r, SpanList& out) const {
    LineRoots lr;
    const bool any = line_roots(r, lr);
    const double len = 1.0 / lr.scale;
    auto inside_at = [&](double t) { return horner(lr.g, t * len - lr.shift) < 0.0; };
    if (!any) {
        // No crossing: the whole line is inside or outside (an unbounded solid may hold it).
        if (!bounds_.finite() && degree_ > 0 && inside_at(0.0))
            out.push_back({{-kInfinity, 0, 0}, {kInfinity, 0, 0}});
        return;
    }
    // Classify the intervals between consecutive roots by the sign of g at their middles;
    // a tangent (double) root has the same sign on both sides and merges away.
    double start = -kInfinity;
    const int n = lr.count;
    bool in = inside_at(lr.t[0] - 1.0 - std::abs(lr.t[0]));
    for (int i = 0; i < n; ++i) {
        const bool after = i + 1 < n ? inside_at(0.5 * (lr.t[i] + lr.t[i + 1]))
                                     : inside_at(lr.t[n - 1] + 1.0 + std::abs(lr.t[n - 1]));
        if (!in && after) start = lr.t[i];
        if (in && !after) out.push_back({{start, 0, 0}, {lr.t[i], 0, 0}});
        in = after;
    }
    if (in) out.push_back({{start, 0, 0}, {kInfinity, 0, 0}});
}

Vec3 AlgebraicShape::normal(const Ray& r, const Crossing& c) const {
    const Vec3 g = f_.gradient(r.at(c.t));
    const double len = length(g);
    // A singular point (cone apex): any normal facing the ray will do.
    return len > 0.0 && std::isfinite(len) ? g / len : normalize(-r.d);
}

}  // namespace lat
