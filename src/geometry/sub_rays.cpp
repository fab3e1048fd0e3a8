#include "geometry/sub_rays.h"

namespace lat {

void across_in_object(const RayFootprint& world, const Affine& inverse, bool identity, bool similar,
                      double widest, RayFootprint& object) {
    object.widest = widest;
    object.across = world.across && (similar || identity);
    if (!object.across) return;
    object.u = identity ? world.u : inverse.vector(world.u);
    object.v = identity ? world.v : inverse.vector(world.v);
}

double LayerComposite::add(double coverage, std::uint8_t sub_rays) {
    const double before = left();
    if (sub_rays == 0) {
        free_ *= 1.0 - coverage;
        ++draws_;
    } else {
        covered_ |= sub_rays;
    }
    return before > 0 ? 1.0 - left() / before : 1.0;
}

}  // namespace lat
