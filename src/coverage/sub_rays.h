#pragma once
// Sub-rays: a lattice answered by its primitive's crossings (lattice/sub_ray_shape.h) offsets
// kSubRays rays across a ray's footprint and reports which of them met it
// (Crossing::sub_rays). Where every lattice offsets them along the same world directions, the
// k-th sub-ray is one ray from object to object, so the partial crossings of a ray compose as
// its sub-rays' own would: a sub-ray blocked by one crossing is not blocked again by the next
// (LayerComposite, coverage/layer_composite.h). Offsets along each object's own axes would make
// the crossings independent draws, and a stack of them would let through or cover the wrong
// share.
#include "math/ray.h"
#include "math/transform.h"

namespace lat {

inline constexpr int kSubRays = 4;  // a 2 x 2 grid

// The accelerator, before testing an object: the object's copy of the world ray's footprint
// (RayFootprint) gets the world's directions across the ray through the object's inverse
// linear map (xf: object -> world), when the world's are set and the map keeps them across the
// ray and as long as it (`similar`: a similarity, within 1e-3; else unset, and the object uses
// its own directions), and the object's widest footprint (RayFootprint::widest). Written in
// place, only these fields (the width, spread and purpose are the world ray's, copied once a
// query): a whole copy built on the stack and handed over stalls store forwarding.
// inverse: xf's inverse map; identity: whether xf is the identity.
void across_in_object(const RayFootprint& world, const Affine& inverse, bool identity, bool similar,
                      double widest, RayFootprint& object);

}  // namespace lat
