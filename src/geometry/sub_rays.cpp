#include "geometry/sub_rays.h"

namespace lat {
namespace {

thread_local AcrossRay t_world, t_object;

}  // namespace

ScopedAcrossRay::ScopedAcrossRay(Vec3 unit_direction) : previous_(t_world) {
    AcrossRay a;
    orthonormal_basis(unit_direction, a.u, a.v);
    a.set = true;
    t_world = a;
}

ScopedAcrossRay::~ScopedAcrossRay() {
    t_world = previous_;
    t_object = {};
}
const AcrossRay& across_ray() { return t_world; }
const AcrossRay& across_ray_in_object() { return t_object; }
void clear_across_ray_in_object() { t_object = {}; }
void set_across_ray_in_object(const Affine& inverse, bool identity, bool similar, double widest) {
    AcrossRay& a = t_object;
    a.widest = widest;
    a.set = t_world.set && (similar || identity);
    if (!a.set) return;
    a.u = identity ? t_world.u : inverse.vector(t_world.u);
    a.v = identity ? t_world.v : inverse.vector(t_world.v);
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
