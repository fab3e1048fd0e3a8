#pragma once
#include <limits>

#include "math/vec.h"

namespace lat {

// What a ray stands for beyond its line: the footprint of a pixel (or of what a shadow ray
// leaves), which picks a filtered lattice's level of detail and spans its sub-rays
// (lattice/filtered_shape.h, lattice/sub_ray_shape.h). The camera makes one with each camera
// ray (TraceRay, render/core/camera.h), shading one with each shadow ray; the accelerator hands each
// object its own copy in the object's space (accel/embree_query.h).
struct RayFootprint {
    // The width (world units) at parameter t of the world ray (unit direction) is
    // width0 + spread * t. 0 (the default) asks for the finest level.
    double width0 = 0, spread = 0;
    // Directions across the ray along which sub-rays are offset (`across`: whether set): unit
    // and perpendicular to the ray and each other in the world; in an object's copy, the
    // world's through the object's inverse map (no longer unit under a scaled instance), or
    // unset where the map does not keep them across the ray (the object then uses its own).
    Vec3 u, v;
    // An object's copy only: the widest footprint (object units) its sub-rays may span, its
    // placement's (AccelObject::widest_footprint), by which its culling was narrowed.
    double widest = std::numeric_limits<double>::infinity();
    bool across = false;
    // The ray wants only each sheet's coverage and where it lies (a shadow ray's
    // transmittance): the normals are not decoded, and the crossing's normal faces the ray.
    bool coverage_only = false;
    // A shadow ray's: how far (parameter t of the world ray, unit direction) its line stays
    // within the camera footprint of the surface it leaves (0: not at all). Along that stretch
    // the camera footprint saw through to the surface, so what a footprint-wide answer finds
    // there mostly lies beside the lines that reached the surface, not on their shadow rays
    // (coverage/footprint.h: unseen_share).
    double seen_until = 0;
};

// A footprint for a world ray of unit direction `unit_direction`, with its directions across.
inline RayFootprint footprint_across(Vec3 unit_direction, double width0, double spread,
                                     bool coverage_only) {
    RayFootprint f;
    f.width0 = width0;
    f.spread = spread;
    orthonormal_basis(unit_direction, f.u, f.v);
    f.across = true;
    f.coverage_only = coverage_only;
    return f;
}

// A ray o + t d. The direction need not be unit length: affine maps keep t unchanged.
// footprint: none (null) for a ray that stands for its line alone (a zero footprint). Not
// owned, and not carried through Transform's maps: only the accelerator hands it to objects.
struct Ray {
    Vec3 o;
    Vec3 d;
    const RayFootprint* footprint = nullptr;

    constexpr Vec3 at(double t) const { return o + d * t; }
};

}  // namespace lat
