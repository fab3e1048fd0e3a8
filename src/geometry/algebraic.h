#pragma once
// Surfaces f(x, y, z) = 0 of degree <= 4 (paper 3.2.1), f < 0 inside, intersected in closed
// form: the ray is restricted to a univariate polynomial and solved by solve_quartic (or the
// quadratic formula for quadrics). Normals are the normalised gradient.
#include "geometry/lattice_source.h"
#include "geometry/poly3.h"
#include "geometry/shape.h"

namespace lat {

class AlgebraicShape final : public Shape, public LatticeSource {
public:
    // bounds: a box known to hold the whole surface (infinite if unbounded); centre: a point
    // near the surface, used to move the ray origin close before solving (the main source of
    // accuracy for far-away rays).
    AlgebraicShape(const Poly3& f, const Bounds3& bounds, Vec3 center);

    // A torus-like extent: every point of the solid lies within `ball` of the circle of radius
    // `ring` about the origin in the plane z = 0 (a torus: major and minor radius; a sphere:
    // ring 0). It makes placed_bounds exact under any transform.
    struct RingExtent {
        double ring = 0, ball = 0;
    };
    AlgebraicShape(const Poly3& f, const Bounds3& bounds, Vec3 center, RingExtent extent);

    const Poly3& polynomial() const { return f_; }
    int degree() const { return degree_; }
    // Its one surface, part 0.
    bool names_surface(const Crossing& c) const override { return c.part == 0; }
    bool cheap_normal(const Crossing&) const override { return degree_ <= 2; }
    // In spheres' tests: a quartic's closed-form solve takes about 12 times a sphere's, a
    // cubic's 9 (quartic_bench: 174, 132 and 14.8 ns a ray).
    double intersect_cost() const override { return degree_ >= 4 ? 12.0 : degree_ == 3 ? 9.0 : 1.0; }

    Bounds3 bounds() const override { return bounds_; }
    Bounds3 placed_bounds(const Transform& xf) const override;
    // With a ring extent, a ring of spheres along the circle (a torus's box sphere holds its
    // hole and more), or the one ball; without, none tighter than the box's.
    bool bounding_spheres(std::vector<BoundingSphere>& out) const override;
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override;
    bool inside(Vec3 p) const override { return f_.eval(p) <= 0.0; }

    // The real roots of f along the ray's whole line, as ray parameters, ascending; also the
    // univariate polynomial g(u) and the map t = (shift + u) * scale used, for sign tests.
    struct LineRoots {
        int count = 0;
        double t[4] = {0, 0, 0, 0};
        double g[5] = {0, 0, 0, 0, 0};
        double shift = 0, scale = 1;
    };
    bool line_roots(const Ray& r, LineRoots& out) const;

private:
    // Whether the line p + u dn, u in [u0, u1], keeps out of the region the ring extent gives.
    bool misses_ring(Vec3 p, Vec3 dn, double u0, double u1) const;

    Poly3 f_;
    Bounds3 bounds_;
    Vec3 center_;
    int degree_;
    bool has_extent_ = false;
    RingExtent extent_;
};

}  // namespace lat
