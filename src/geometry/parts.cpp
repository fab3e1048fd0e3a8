#include "geometry/parts.h"

#include "geometry/lattice_source.h"

namespace lat {

void ShapeParts::part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
    if (parts_) return parts_->part_spheres(i, out);
    const auto* source = dynamic_cast<const LatticeSource*>(shape_);
    if (source && source->bounding_spheres(out)) return;
    out.push_back(sphere_around(shape_->bounds()));
}

}  // namespace lat
