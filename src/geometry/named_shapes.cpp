#include "geometry/named_shapes.h"

#include <cmath>

#include "geometry/algebraic.h"
#include "geometry/halfspace.h"
#include "geometry/poly3.h"
#include "geometry/sphere.h"

namespace lat {
namespace {

PlacedShape algebraic(const Poly3& f, const Bounds3& bounds, const Transform& placement) {
    return {std::make_shared<AlgebraicShape>(f, bounds, bounds.finite() ? bounds.center() : Vec3{}),
            placement};
}

// x²/a² + y²/b² + cz z² + lz z + k
Poly3 quadric(double a, double b, double cz, double lz, double k) {
    Poly3 f;
    f.at(2, 0, 0) = 1.0 / (a * a);
    f.at(0, 2, 0) = 1.0 / (b * b);
    f.at(0, 0, 2) = cz;
    f.at(0, 0, 1) = lz;
    f.at(0, 0, 0) = k;
    return f;
}

}  // namespace

Transform frame_transform(Vec3 center, Vec3 axis) {
    const Vec3 z{0, 0, 1};
    const Vec3 a = normalize(axis);
    const Vec3 c = cross(z, a);
    const double s = length(c), cosang = dot(z, a);
    Transform rot;
    if (s > 1e-12) rot = Transform::rotate(c, std::atan2(s, cosang));
    else if (cosang < 0) rot = Transform::rotate({1, 0, 0}, M_PI);
    return Transform::translate(center) * rot;
}

PlacedShape make_sphere(Vec3 center, double radius) {
    return {std::make_shared<SphereShape>(center, radius), Transform{}};
}

PlacedShape make_ellipsoid(Vec3 center, Vec3 radii) {
    // A unit sphere scaled: the sphere's robust solver, and exact normals by inverse transpose.
    return {std::make_shared<SphereShape>(Vec3{}, 1.0),
            Transform::translate(center) * Transform::scale(radii)};
}

PlacedShape make_halfspace(Vec3 point, Vec3 normal) {
    return {std::make_shared<HalfSpaceShape>(point, normal), Transform{}};
}

PlacedShape make_cylinder(Vec3 center, Vec3 axis, double a, double b) {
    return algebraic(quadric(a, b, 0, 0, -1), Bounds3::infinite(), frame_transform(center, axis));
}

PlacedShape make_cone(Vec3 apex, Vec3 axis, double a, double b) {
    return algebraic(quadric(a, b, -1, 0, 0), Bounds3::infinite(), frame_transform(apex, axis));
}

PlacedShape make_paraboloid(Vec3 vertex, Vec3 axis, double a, double b) {
    return algebraic(quadric(a, b, 0, -1, 0), Bounds3::infinite(), frame_transform(vertex, axis));
}

PlacedShape make_hyperboloid1(Vec3 center, Vec3 axis, Vec3 r) {
    return algebraic(quadric(r.x, r.y, -1.0 / (r.z * r.z), 0, -1), Bounds3::infinite(),
                     frame_transform(center, axis));
}

PlacedShape make_hyperboloid2(Vec3 center, Vec3 axis, Vec3 r) {
    return algebraic(quadric(r.x, r.y, -1.0 / (r.z * r.z), 0, 1), Bounds3::infinite(),
                     frame_transform(center, axis));
}

PlacedShape make_torus(Vec3 center, Vec3 axis, double R, double r) {
    // (x²+y²+z²+R²-r²)² - 4R²(x²+y²), expanded.
    Poly3 f;
    const double k = R * R - r * r;
    f.at(4, 0, 0) = f.at(0, 4, 0) = f.at(0, 0, 4) = 1;
    f.at(2, 2, 0) = f.at(2, 0, 2) = f.at(0, 2, 2) = 2;
    f.at(2, 0, 0) = f.at(0, 2, 0) = 2 * k - 4 * R * R;
    f.at(0, 0, 2) = 2 * k;
    f.at(0, 0, 0) = k * k;
    const double e = R + r;
    const Bounds3 box{{-e, -e, -r}, {e, e, r}};
    return {std::make_shared<AlgebraicShape>(f, box, Vec3{}, AlgebraicShape::RingExtent{R, r}),
            frame_transform(center, axis)};
}

PlacedShape make_algebraic(const Poly3& f, const Bounds3& bounds) {
    return algebraic(f, bounds, Transform{});
}

}  // namespace lat
