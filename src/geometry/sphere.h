#pragma once
#include "geometry/shape.h"

namespace lat {

struct RayQuad;
struct QuadCrossings;
struct RayFan;
struct FanHits;

class SphereShape final : public Shape {
public:
    SphereShape(Vec3 center, double radius) : c_(center), r_(radius) {}

    Vec3 center() const { return c_; }
    double radius() const { return r_; }

    Bounds3 bounds() const override;
    Bounds3 placed_bounds(const Transform& xf) const override;
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override;
    bool inside(Vec3 p) const override { return length_squared(p - c_) <= r_ * r_; }

    // Both crossings t0 <= t1 of the ray's line, if it meets the sphere.
    bool solve(const Ray& r, double& t0, double& t1) const;

    // Four parallel rays at once (geometry/ray_quad.h), each lane as the scalar test answers it:
    // the lanes in `live` that intersect() finds a crossing for, their crossings kept in hits
    // and their tmax narrowed to them; and the lanes in `live` that occluded() blocks.
    unsigned intersect_quad(RayQuad& q, unsigned live, QuadCrossings& hits) const;
    unsigned occluded_quad(const RayQuad& q, unsigned live) const;
    // Two rays from one origin at once (geometry/ray_fan.h): the lanes (bits 0, 1) that
    // intersect() finds a crossing for, and their crossings in out, as the scalar test's.
    unsigned intersect_fan(const RayFan& f, FanHits& out) const;

private:
    Vec3 c_;
    double r_;
};

// The sphere s is, if it is one: the typed view for what needs its centre and radius (the
// texture baseline's atlas).
const SphereShape* as_sphere(const Shape& s);

}  // namespace lat
