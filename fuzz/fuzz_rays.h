#pragma once
// Shared by the harnesses: traces a few fixed rays through a shape, as the renderer would
// (intersect, then the normal at the hit), so that parsed geometry is also exercised.
#include "geometry/shape.h"
#include "math/transform.h"

namespace lat::fuzz {

inline void trace_a_few_rays(const Shape& shape, const Transform& xf) {
    const Vec3 origins[] = {{0, -10, 1}, {3, 4, -5}, {0.5, 0.25, 20}, {-7, 0.1, 0}};
    for (const Vec3& o : origins) {
        const Ray world{o, -o};  // towards the origin
        const Ray r = xf.is_identity() ? world : xf.inverse_ray(world);
        Crossing c;
        if (shape.intersect(r, 0.0, kInfinity, c)) (void)shape.normal(r, c);
        (void)shape.occluded(r, 1e-9, kInfinity);
    }
}

}  // namespace lat::fuzz
