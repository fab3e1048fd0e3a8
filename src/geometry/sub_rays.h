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

// The accelerator, before testing an object: the object's copy of the world ray's footprint
// (RayFootprint) gets the world's directions across the ray through the object's inverse
// linear map (xf: object -> world), when the world's are set and the map keeps them across the
// ray and as long as it (`similar`: a similarity, within 1e-3; else unset, and the object uses
// its own directions), and the object's widest footprint (RayFootprint::widest). Written in
// place, only these fields (the width, spread and purpose are the world ray's, copied once a
// query): a whole copy built on the stack and handed over stalled store forwarding.
// inverse: xf's inverse map; identity: whether xf is the identity.
void across_in_object(const RayFootprint& world, const Affine& inverse, bool identity, bool similar,
                      double widest, RayFootprint& object);

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
