#include "geometry/sphere.h"

#include <cmath>

namespace lat {

Bounds3 SphereShape::bounds() const {
    const Vec3 e{r_, r_, r_};
    return {c_ - e, c_ + e};
}

Bounds3 SphereShape::placed_bounds(const Transform& xf) const {
    // An ellipsoid's half-extent along world axis i is r |row_i(M)|.
    const Affine& a = xf.forward();
    const Vec3 e{r_ * length(a.m.r[0]), r_ * length(a.m.r[1]), r_ * length(a.m.r[2])};
    const Vec3 c = xf.point(c_);
    return {c - e, c + e};
}

bool SphereShape::solve(const Ray& r, double& t0, double& t1) const {
    // Hearn & Baker's form: the discriminant from the squared distance of the line to the
    // centre, which stays accurate for far origins and grazing rays (Ray Tracing Gems, ch. 7).
    const double dd = length_squared(r.d);
    if (dd == 0.0) return false;
    const Vec3 f = r.o - c_;
    const double b = -dot(f, r.d) / dd;  // parameter of the point closest to the centre
    const Vec3 perp = f + r.d * b;
    // Solids are closed: a ray that touches the surface hits it (the paper's counts of Table 1
    // depend on it); the tolerance absorbs the rounding of exact tangencies.
    double disc = r_ * r_ - length_squared(perp);
    if (disc < -kTouchTolerance * r_ * r_) return false;
    disc = std::max(disc, 0.0);
    const double h = std::sqrt(disc / dd);
    // Stable pair: the larger-magnitude root directly, the other from the product c/a.
    const double c = (length_squared(f) - r_ * r_) / dd;
    const double q = b + std::copysign(h, b);
    if (q == 0.0) {
        t0 = t1 = 0.0;
    } else {
        t0 = q;
        t1 = c / q;
        if (t0 > t1) std::swap(t0, t1);
    }
    return true;
}

bool SphereShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    double t0, t1;
    if (!solve(r, t0, t1)) return false;
    const double t = t0 > tmin ? t0 : t1;
    if (t <= tmin || t >= tmax) return false;
    hit = {t, 0, 0};
    return true;
}

bool SphereShape::occluded(const Ray& r, double tmin, double tmax) const {
    double t0, t1;
    if (!solve(r, t0, t1)) return false;
    return (t0 > tmin && t0 < tmax) || (t1 > tmin && t1 < tmax);
}

void SphereShape::spans(const Ray& r, SpanList& out) const {
    double t0, t1;
    if (solve(r, t0, t1) && t0 < t1) out.push_back({{t0, 0, 0}, {t1, 0, 0}});
}

Vec3 SphereShape::normal(const Ray& r, const Crossing& c) const {
    return (r.at(c.t) - c_) / r_;
}

}  // namespace lat
