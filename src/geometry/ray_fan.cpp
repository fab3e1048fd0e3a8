#include "geometry/ray_fan.h"

#include "geometry/capped_cylinder.h"
#include "geometry/sphere.h"

namespace lat {

using namespace quad;

namespace {

// The lanes (of a fan) whose crossing t lies in (tmin, tmax), NaN-safe as the scalar
// comparisons are.
V within(V t, const RayFan& f) {
    return _mm_and_pd(_mm_cmpgt_pd(t, f.tmin), _mm_cmplt_pd(t, f.tmax));
}

}  // namespace

// SphereShape::solve, then intersect(), lane by lane.
unsigned SphereShape::intersect_fan(const RayFan& f, FanHits& out) const {
    const V zero = _mm_setzero_pd();
    const V dd = dot(f.d, f.d);
    const Vec3 w = f.o - c_;
    const V b = -dot(f.d, w) / dd;
    const V3 perp{splat(w.x) + f.d.x * b, splat(w.y) + f.d.y * b, splat(w.z) + f.d.z * b};
    const V disc = splat(r_ * r_) - dot(perp, perp);
    V met = _mm_and_pd(_mm_cmpneq_pd(dd, zero), _mm_cmpnlt_pd(disc, splat(-kTouchTolerance * r_ * r_)));
    if (!bits(met)) {  // both lanes' lines pass the sphere by
        out.t = out.part = zero;
        return 0;
    }
    const V h = _mm_sqrt_pd(max0(disc) / dd);
    const V c = splat(length_squared(w) - r_ * r_) / dd;
    const V q = b + copysign(h, b);
    const V other = c / q;
    const V swap = _mm_cmpgt_pd(q, other), qzero = _mm_cmpeq_pd(q, zero);
    const V t0 = _mm_andnot_pd(qzero, pick(swap, other, q));
    const V t1 = _mm_andnot_pd(qzero, pick(swap, q, other));
    const V t = pick(_mm_cmpgt_pd(t0, f.tmin), t0, t1);
    met = _mm_and_pd(met, _mm_and_pd(_mm_cmpnle_pd(t, f.tmin), _mm_cmpnge_pd(t, f.tmax)));
    out.t = t, out.part = zero;
    return bits(met);
}

// CappedCylinderShape::solve, then intersect(), lane by lane.
unsigned CappedCylinderShape::intersect_fan(const RayFan& f, FanHits& out) const {
    const V zero = _mm_setzero_pd();
    const Vec3 w = f.o - a_;
    const double wa = dot(w, axis_);
    const V da = dot(f.d, axis_);
    const Vec3 wp = w - axis_ * wa;
    const V3 dp{f.d.x - splat(axis_.x) * da, f.d.y - splat(axis_.y) * da, f.d.z - splat(axis_.z) * da};
    V met = _mm_castsi128_pd(_mm_set1_epi64x(-1));

    // Infinite cylinder, in the stable closest-point form; a lane along the axis lies within
    // the radius or misses. Where both lanes' lines pass it by, nothing else need be worked out.
    const V A = dot(dp, dp);
    const V slanted = _mm_cmpgt_pd(A, zero);
    const V b = -dot(dp, wp) / A;
    const V3 pp{splat(wp.x) + dp.x * b, splat(wp.y) + dp.y * b, splat(wp.z) + dp.z * b};
    const V disc = splat(r_ * r_) - dot(pp, pp);
    const V side_met = _mm_cmpnlt_pd(disc, splat(-kTouchTolerance * r_ * r_));
    const V axial_met = length_squared(wp) > r_ * r_ ? zero : met;
    if (!bits(pick(slanted, side_met, axial_met))) {
        out.t = out.part = zero;
        return 0;
    }

    // Slab between the two end planes; a lane parallel to them lies between them or misses.
    const V flat = _mm_cmpeq_pd(da, zero);
    const V n0 = splat(-wa) / da, n1 = splat(len_ - wa) / da;
    const V swap = _mm_cmpgt_pd(n0, n1);
    const V s0 = pick(flat, splat(-kInfinity), pick(swap, n1, n0));
    const V s1 = pick(flat, splat(kInfinity), pick(swap, n0, n1));
    const V s0part = pick(flat, splat(1), pick(swap, splat(2), splat(1)));
    const V s1part = pick(flat, splat(2), pick(swap, splat(1), splat(2)));
    if (wa < 0.0 || wa > len_) met = _mm_andnot_pd(flat, met);

    const V h = _mm_sqrt_pd(max0(disc) / A);
    const V c = splat(length_squared(wp) - r_ * r_) / A;
    const V q = b + copysign(h, b);
    const V other = c / q;
    const V rswap = _mm_cmpgt_pd(q, other), qzero = _mm_cmpeq_pd(q, zero);
    const V c0 = pick(slanted, _mm_andnot_pd(qzero, pick(rswap, other, q)), splat(-kInfinity));
    const V c1 = pick(slanted, _mm_andnot_pd(qzero, pick(rswap, q, other)), splat(kInfinity));
    met = _mm_and_pd(met, pick(slanted, side_met, axial_met));

    const V side_in = _mm_cmpgt_pd(c0, s0), side_out = _mm_cmplt_pd(c1, s1);
    const V tin = pick(side_in, c0, s0), pin = _mm_andnot_pd(side_in, s0part);
    const V tout = pick(side_out, c1, s1), pout = _mm_andnot_pd(side_out, s1part);
    met = _mm_and_pd(met, _mm_cmple_pd(tin, tout));
    const V in_ok = _mm_and_pd(met, within(tin, f)), out_ok = _mm_and_pd(met, within(tout, f));
    out.t = pick(in_ok, tin, tout), out.part = pick(in_ok, pin, pout);
    return bits(_mm_or_pd(in_ok, out_ok));
}

}  // namespace lat
