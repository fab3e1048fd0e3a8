#include "geometry/halfspace.h"

#include <cmath>

namespace lat {

Bounds3 HalfSpaceShape::bounds() const {
    // An axis-aligned half-space is bounded on one side; keep that, it helps CSG bounds.
    Bounds3 b = Bounds3::infinite();
    for (std::size_t a = 0; a < 3; ++a) {
        const double na = n_[a];
        if (std::abs(na) == 1.0) {
            if (na > 0) b.hi[a] = p_[a];
            else b.lo[a] = p_[a];
        }
    }
    return b;
}

double HalfSpaceShape::crossing_t(const Ray& r) const {
    const double dn = dot(r.d, n_);
    return dn == 0.0 ? std::nan("") : dot(p_ - r.o, n_) / dn;
}

bool HalfSpaceShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    const double t = crossing_t(r);
    if (!(t > tmin && t < tmax)) return false;  // also NaN: parallel
    hit = {t, 0, 0};
    return true;
}

bool HalfSpaceShape::occluded(const Ray& r, double tmin, double tmax) const {
    const double t = crossing_t(r);
    return t > tmin && t < tmax;
}

void HalfSpaceShape::spans(const Ray& r, SpanList& out) const {
    const double dn = dot(r.d, n_);
    const double g0 = dot(r.o - p_, n_);
    if (dn == 0.0) {
        if (g0 <= 0.0) out.push_back({{-kInfinity, 0, 0}, {kInfinity, 0, 0}});
        return;
    }
    const double t = -g0 / dn;
    if (dn > 0.0) out.push_back({{-kInfinity, 0, 0}, {t, 0, 0}});
    else out.push_back({{t, 0, 0}, {kInfinity, 0, 0}});
}

}  // namespace lat
