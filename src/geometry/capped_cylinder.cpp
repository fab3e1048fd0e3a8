#include "geometry/capped_cylinder.h"

#include <cassert>
#include <cmath>

#include "geometry/ray_quad.h"

namespace lat {

CappedCylinderShape::CappedCylinderShape(Vec3 a, Vec3 b, double radius)
    : a_(a), b_(b), len_(length(b - a)), r_(radius) {
    assert(len_ > 0.0 && radius > 0.0);
    axis_ = (b - a) / len_;
}

Bounds3 CappedCylinderShape::bounds() const {
    // Exact box of the two end discs: per axis, the disc half-extent is r * sqrt(1 - a_i^2).
    Vec3 e;
    for (std::size_t i = 0; i < 3; ++i) e[i] = r_ * std::sqrt(std::max(0.0, 1.0 - axis_[i] * axis_[i]));
    return {min(a_, b_) - e, max(a_, b_) + e};
}

Bounds3 CappedCylinderShape::placed_bounds(const Transform& xf) const {
    // Each end disc maps to an ellipse with half-extent r sqrt(|row_i|^2 - (row_i . axis)^2).
    const Affine& a = xf.forward();
    Vec3 e;
    for (std::size_t i = 0; i < 3; ++i) {
        const double ra = dot(a.m.r[i], axis_);
        e[i] = r_ * std::sqrt(std::max(0.0, length_squared(a.m.r[i]) - ra * ra));
    }
    const Vec3 pa = xf.point(a_), pb = xf.point(b_);
    return {min(pa, pb) - e, max(pa, pb) + e};
}

bool CappedCylinderShape::solve(const Ray& r, Crossing& in, Crossing& out) const {
    const Vec3 w = r.o - a_;
    const double wa = dot(w, axis_), da = dot(r.d, axis_);
    const Vec3 wp = w - axis_ * wa, dp = r.d - axis_ * da;

    // Slab between the two end planes.
    double s0 = -kInfinity, s1 = kInfinity;
    std::uint32_t s0part = 1, s1part = 2;
    if (da != 0.0) {
        s0 = -wa / da;
        s1 = (len_ - wa) / da;
        if (s0 > s1) {
            std::swap(s0, s1);
            std::swap(s0part, s1part);
        }
    } else if (wa < 0.0 || wa > len_) {
        return false;
    }

    // Infinite cylinder: |wp + t dp|^2 = r^2, solved in the stable closest-point form.
    double c0 = -kInfinity, c1 = kInfinity;
    const double A = length_squared(dp);
    if (A > 0.0) {
        const double b = -dot(wp, dp) / A;
        double disc = r_ * r_ - length_squared(wp + dp * b);
        if (disc < -kTouchTolerance * r_ * r_) return false;  // closed solid, as for spheres
        disc = std::max(disc, 0.0);
        const double h = std::sqrt(disc / A);
        const double c = (length_squared(wp) - r_ * r_) / A;
        const double q = b + std::copysign(h, b);
        if (q == 0.0) {
            c0 = c1 = 0.0;
        } else {
            c0 = q;
            c1 = c / q;
            if (c0 > c1) std::swap(c0, c1);
        }
    } else if (length_squared(wp) > r_ * r_) {
        return false;
    }

    in = c0 > s0 ? Crossing{c0, 0, 0} : Crossing{s0, s0part, 0};
    out = c1 < s1 ? Crossing{c1, 0, 0} : Crossing{s1, s1part, 0};
    return in.t <= out.t;  // equal: the ray touches the side or the rim of an end
}

bool CappedCylinderShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    Crossing in, out;
    if (!solve(r, in, out)) return false;
    if (in.t > tmin && in.t < tmax) {
        hit = in;
        return true;
    }
    if (out.t > tmin && out.t < tmax) {
        hit = out;
        return true;
    }
    return false;
}

void CappedCylinderShape::spans(const Ray& r, SpanList& spans) const {
    Crossing in, out;
    if (solve(r, in, out) && in.t < out.t) spans.push_back({in, out});
}

Vec3 CappedCylinderShape::normal(const Ray& r, const Crossing& c) const {
    if (c.part == 1) return -axis_;
    if (c.part == 2) return axis_;
    const Vec3 w = r.at(c.t) - a_;
    const Vec3 radial = w - axis_ * dot(w, axis_);
    const double len = length(radial);
    return len > 0.0 ? radial / len : normalize(-r.d);
}

bool CappedCylinderShape::inside(Vec3 p) const {
    const Vec3 w = p - a_;
    const double wa = dot(w, axis_);
    return wa >= 0.0 && wa <= len_ && length_squared(w - axis_ * wa) <= r_ * r_;
}

namespace {

// Lanes of solve()'s crossings in and out, with their surfaces (as doubles).
struct QuadSpan {
    quad::V tin, tout, pin, pout;
};

// solve() for lanes h, h + 1 of q: the lanes where the line meets the cylinder, and their
// span. What depends on the direction alone, shared by the lanes, is tested once.
quad::V solve_pair(const RayQuad& q, int h, Vec3 a, Vec3 axis, double len, double radius,
                    QuadSpan& span) {
    using namespace quad;
    const V3 w = origins_minus(q, h, a);
    const V wa = dot(w, axis);
    const double da = dot(q.d, axis);
    const V3 wp{w.x - splat(axis.x) * wa, w.y - splat(axis.y) * wa, w.z - splat(axis.z) * wa};
    const Vec3 dp = q.d - axis * da;
    V met = all_lanes();

    // Slab between the two end planes.
    V s0 = splat(-kInfinity), s1 = splat(kInfinity), s0part = splat(1), s1part = splat(2);
    if (da != 0.0) {
        const V n0 = -wa / splat(da), n1 = (splat(len) - wa) / splat(da);
        const V swap = _mm_cmpgt_pd(n0, n1);
        s0 = pick(swap, n1, n0), s1 = pick(swap, n0, n1);
        s0part = pick(swap, splat(2), splat(1)), s1part = pick(swap, splat(1), splat(2));
    } else {
        met = _mm_andnot_pd(_mm_or_pd(_mm_cmplt_pd(wa, _mm_setzero_pd()), _mm_cmpgt_pd(wa, splat(len))), met);
    }

    // Infinite cylinder.
    V c0 = splat(-kInfinity), c1 = splat(kInfinity);
    if (const double A = length_squared(dp); A > 0.0) {
        met = _mm_and_pd(met, line_roots(wp, dp, A, radius, c0, c1));
    } else {
        met = _mm_andnot_pd(_mm_cmpgt_pd(dot(wp, wp), splat(radius * radius)), met);
    }

    const V side_in = _mm_cmpgt_pd(c0, s0), side_out = _mm_cmplt_pd(c1, s1);
    span.tin = pick(side_in, c0, s0), span.pin = _mm_andnot_pd(side_in, s0part);
    span.tout = pick(side_out, c1, s1), span.pout = _mm_andnot_pd(side_out, s1part);
    return _mm_and_pd(met, _mm_cmple_pd(span.tin, span.tout));
}

// The lanes (of h, h + 1) in `live` whose entry (in_ok) or else exit (out_ok) lies in their
// range: the crossing intersect() answers with, if any.
struct QuadCrossing {
    QuadSpan span;
    quad::V in_ok, out_ok;
};
QuadCrossing crossing_pair(const RayQuad& q, int h, unsigned live, Vec3 a, Vec3 axis,
                           double len, double radius) {
    using namespace quad;
    QuadCrossing x;
    const V met =
        _mm_and_pd(solve_pair(q, h, a, axis, len, radius, x.span), mask_of(live >> h & 3u));
    const V tmin = load(q.tmin + h), tmax = load(q.tmax + h);
    const auto within = [&](V t) {
        return _mm_and_pd(_mm_cmpgt_pd(t, tmin), _mm_cmplt_pd(t, tmax));
    };
    x.in_ok = _mm_and_pd(met, within(x.span.tin));
    x.out_ok = _mm_and_pd(met, within(x.span.tout));
    return x;
}

}  // namespace

unsigned CappedCylinderShape::intersect_quad(RayQuad& q, unsigned live, QuadCrossings& hits) const {
    using namespace quad;
    unsigned found = 0;
    for (int h = 0; h < 4; h += 2) {
        if ((live >> h & 3u) == 0) continue;
        const QuadCrossing x = crossing_pair(q, h, live, a_, axis_, len_, r_);
        const V t = pick(x.in_ok, x.span.tin, x.span.tout);
        const V part = pick(x.in_ok, x.span.pin, x.span.pout);
        found |= keep(q, hits, h, _mm_or_pd(x.in_ok, x.out_ok), t, part);
    }
    return found;
}

unsigned CappedCylinderShape::occluded_quad(const RayQuad& q, unsigned live) const {
    unsigned blocked = 0;
    for (int h = 0; h < 4; h += 2) {
        if ((live >> h & 3u) == 0) continue;
        const QuadCrossing x = crossing_pair(q, h, live, a_, axis_, len_, r_);
        blocked |= quad::bits(_mm_or_pd(x.in_ok, x.out_ok)) << h;
    }
    return blocked;
}

}  // namespace lat
