#pragma once
// Sub-rays: a filtered lattice answered by its primitive's crossings (lattice/filtered_shape.h)
// offsets kSubRays rays across a ray's footprint and reports which of them met it
// (Crossing::sub_rays). Where every lattice offsets them along the same world directions, the
// k-th sub-ray is one ray from object to object, so the partial crossings of a ray compose as
// its sub-rays' own would: a sub-ray blocked by one crossing is not blocked again by the next
// (LayerComposite). Offsets along each object's own axes (as the first version did) made the
// crossings independent draws, and a stack of them let through or covered the wrong share.
#include <bit>
#include <cstdint>

#include "geometry/shape.h"
#include "math/transform.h"

namespace lat {

inline constexpr int kSubRays = 4;  // a 2 x 2 grid

// The directions across a ray along which its sub-rays are offset: unit, perpendicular to the
// ray and to each other, in world space as the renderer set them (`set`: whether it did), and
// in the space of the object being tested, as the accelerator hands them on per object (its
// inverse transform applied; no longer unit under a scaled instance).
struct AcrossRay {
    Vec3 u, v;
    bool set = false;
    // The object's copy only (what the accelerator hands an object about the ray): the widest
    // footprint (object units) its sub-rays may span, its placement's
    // (AccelObject::widest_footprint), by which its culling was narrowed.
    double widest = kInfinity;
};
const AcrossRay& across_ray();
// Sets the directions across a ray (unit direction) for a scope: the previous ones after it,
// and no object copy (so that a shape tested directly, outside a traversal, never sees a
// stale one).
class ScopedAcrossRay {
public:
    explicit ScopedAcrossRay(Vec3 unit_direction);
    ~ScopedAcrossRay();
    ScopedAcrossRay(const ScopedAcrossRay&) = delete;
    ScopedAcrossRay& operator=(const ScopedAcrossRay&) = delete;

private:
    AcrossRay previous_;
};
// The accelerator: before testing an object, its own copy: the world one's directions through
// the object's inverse linear map (xf: object -> world), when set and when the map keeps them
// across the ray and as long as it (`similar`: a similarity, within 1e-3; else unset, and the
// object uses its own directions), and the object's widest footprint (AcrossRay::widest).
// Written in place: a copy built on the caller's stack and handed over stalled store
// forwarding (4 % of a candidates lattice's samples).
// inverse: xf's inverse map; identity: whether xf is the identity.
void set_across_ray_in_object(const Affine& inverse, bool identity, bool similar, double widest);
// After a query: no object copy, so that a shape tested directly never sees the last object's.
void clear_across_ray_in_object();
const AcrossRay& across_ray_in_object();

// Partial crossings of one ray composed: what is left of it after each, front to back (camera
// rays), or in any order (a shadow ray's transmittance, which does not depend on it).
// Crossings without sub-rays are taken as independent of the rest; those with sub-rays block
// only sub-rays not blocked already.
class LayerComposite {
public:
    // The share of what was left that a crossing of this coverage and these sub-rays
    // (Crossing::sub_rays) covers, and adds it.
    double add(double coverage, std::uint8_t sub_rays);
    double add(const Crossing& c) { return add(double(c.coverage), c.sub_rays); }
    // The share of the ray left.
    double left() const {
        return free_ * double(kSubRays - std::popcount(unsigned(covered_))) / kSubRays;
    }
    // How many crossings without sub-rays were added: what a limit on the layers of a ray
    // counts (one with sub-rays that blocks none not blocked already adds nothing, and all its
    // sub-rays blocked end a ray).
    int draws() const { return draws_; }

private:
    double free_ = 1;            // the product of (1 - coverage) of crossings without sub-rays
    std::uint8_t covered_ = 0;  // the sub-rays blocked
    int draws_ = 0;
};

}  // namespace lat
