#pragma once
// The named quartic surfaces of the scene format. Each is built in a canonical frame (axis
// along z, centre at the origin) and placed by a transform from its centre and axis, so the
// solver always works near the origin, where it is most accurate.
#include <memory>

#include "geometry/poly3.h"
#include "geometry/shape.h"
#include "math/transform.h"

namespace lat {

struct PlacedShape {
    std::shared_ptr<const Shape> shape;
    Transform placement;  // canonical frame -> object frame
};

// A rotation taking +z to the unit vector `axis`, then a translation to `center`.
Transform frame_transform(Vec3 center, Vec3 axis);

PlacedShape make_sphere(Vec3 center, double radius);
PlacedShape make_ellipsoid(Vec3 center, Vec3 radii);
PlacedShape make_halfspace(Vec3 point, Vec3 normal);
// Surfaces along `axis` through `center`, with semi-axes a and b across it:
PlacedShape make_cylinder(Vec3 center, Vec3 axis, double a, double b);  // x²/a²+y²/b² = 1
PlacedShape make_cone(Vec3 apex, Vec3 axis, double a, double b);        // x²/a²+y²/b² = z²
PlacedShape make_paraboloid(Vec3 vertex, Vec3 axis, double a, double b);  // x²/a²+y²/b² = z
PlacedShape make_hyperboloid1(Vec3 center, Vec3 axis, Vec3 radii);  // x²/a²+y²/b²-z²/c² = 1
PlacedShape make_hyperboloid2(Vec3 center, Vec3 axis, Vec3 radii);  // x²/a²+y²/b²-z²/c² = -1
PlacedShape make_torus(Vec3 center, Vec3 axis, double major, double minor);
// A general polynomial; bounds may be infinite.
PlacedShape make_algebraic(const Poly3& f, const Bounds3& bounds);

}  // namespace lat
