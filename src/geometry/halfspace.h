#pragma once
#include "geometry/shape.h"

namespace lat {

// The solid of points x with dot(x - point, normal) <= 0; the normal points out of the solid.
class HalfSpaceShape final : public Shape {
public:
    HalfSpaceShape(Vec3 point, Vec3 normal) : p_(point), n_(normalize(normal)) {}

    Bounds3 bounds() const override;
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    // A floor is tested outside the accelerator by every shadow ray: no Crossing to fill.
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray&, const Crossing&) const override { return n_; }
    bool inside(Vec3 x) const override { return dot(x - p_, n_) <= 0.0; }

private:
    Vec3 p_, n_;
    // The parameter where the ray's line crosses the plane; NaN when it runs parallel.
    double crossing_t(const Ray& r) const;
};

}  // namespace lat
