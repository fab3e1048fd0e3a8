#include "geometry/sphere.h"

#include <cmath>

#include "geometry/ray_quad.h"

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

namespace {

// solve() for lanes h, h + 1 of q: the lanes where the line meets the sphere, and t0 <= t1.
quad::V solve_pair(const RayQuad& q, int h, Vec3 c, double r, quad::V& t0, quad::V& t1) {
    return quad::line_roots(quad::origins_minus(q, h, c), q.d, length_squared(q.d), r, t0, t1);
}

}  // namespace

unsigned SphereShape::intersect_quad(RayQuad& q, unsigned live, QuadCrossings& hits) const {
    using namespace quad;
    if (length_squared(q.d) == 0.0) return 0;
    unsigned found = 0;
    for (int h = 0; h < 4; h += 2) {
        if ((live >> h & 3u) == 0) continue;
        V t0, t1;
        const V met = solve_pair(q, h, c_, r_, t0, t1);
        const V tmin = load(q.tmin + h), tmax = load(q.tmax + h);
        const V t = pick(_mm_cmpgt_pd(t0, tmin), t0, t1);
        const V in_range = _mm_and_pd(_mm_cmpnle_pd(t, tmin), _mm_cmpnge_pd(t, tmax));
        const V hit = _mm_and_pd(_mm_and_pd(met, in_range), mask_of(live >> h & 3u));
        found |= keep(q, hits, h, hit, t, _mm_setzero_pd());
    }
    return found;
}

unsigned SphereShape::occluded_quad(const RayQuad& q, unsigned live) const {
    using namespace quad;
    if (length_squared(q.d) == 0.0) return 0;
    unsigned blocked = 0;
    for (int h = 0; h < 4; h += 2) {
        if ((live >> h & 3u) == 0) continue;
        V t0, t1;
        const V met = solve_pair(q, h, c_, r_, t0, t1);
        const V tmin = load(q.tmin + h), tmax = load(q.tmax + h);
        const V in0 = _mm_and_pd(_mm_cmpgt_pd(t0, tmin), _mm_cmplt_pd(t0, tmax));
        const V in1 = _mm_and_pd(_mm_cmpgt_pd(t1, tmin), _mm_cmplt_pd(t1, tmax));
        const V hit = _mm_and_pd(_mm_and_pd(met, _mm_or_pd(in0, in1)), mask_of(live >> h & 3u));
        blocked |= bits(hit) << h;
    }
    return blocked;
}

const SphereShape* as_sphere(const Shape& s) { return dynamic_cast<const SphereShape*>(&s); }

}  // namespace lat
