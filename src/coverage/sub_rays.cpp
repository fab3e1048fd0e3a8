#include "coverage/sub_rays.h"

namespace lat {

void across_in_object(const RayFootprint& world, const Affine& inverse, bool identity, bool similar,
                      double widest, RayFootprint& object) {
    object.widest = widest;
    object.across = world.across && (similar || identity);
    if (!object.across) return;
    object.u = identity ? world.u : inverse.vector(world.u);
    object.v = identity ? world.v : inverse.vector(world.v);
}

}  // namespace lat
