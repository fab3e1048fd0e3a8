#pragma once
#include "geometry/lattice_source.h"
#include "geometry/shape.h"

namespace lat {

struct RayQuad;
struct QuadCrossings;
struct RayFan;
struct FanHits;

// A finite cylinder of radius r whose axis runs from a to b, with flat ends.
// Crossing::part: 0 the side, 1 the end at a, 2 the end at b.
class CappedCylinderShape final : public Shape, public LatticeSource {
public:
    CappedCylinderShape(Vec3 a, Vec3 b, double radius);

    Bounds3 bounds() const override;
    Bounds3 placed_bounds(const Transform& xf) const override;
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override;
    // The side (0) and the two caps (1, 2).
    bool names_surface(const Crossing& c) const override { return c.part <= 2; }
    double intersect_cost() const override { return 1.0; }
    bool inside(Vec3 p) const override;

    // The span of the ray's line inside the cylinder, if any (t0 < t1, parts as above).
    bool solve(const Ray& r, Crossing& in, Crossing& out) const;

    // Four parallel rays at once (geometry/ray_quad.h), each lane as the scalar test answers it:
    // the lanes in `live` that intersect() finds a crossing for, their crossings kept in hits
    // and their tmax narrowed to them; and the lanes in `live` that occluded() blocks.
    unsigned intersect_quad(RayQuad& q, unsigned live, QuadCrossings& hits) const;
    unsigned occluded_quad(const RayQuad& q, unsigned live) const;
    // Two rays from one origin at once (geometry/ray_fan.h): the lanes (bits 0, 1) that
    // intersect() finds a crossing for, and their crossings in out, as the scalar test's.
    unsigned intersect_fan(const RayFan& f, FanHits& out) const;

private:
    Vec3 a_, b_, axis_;  // axis_ is the unit vector from a to b
    double len_, r_;
};

}  // namespace lat
