#include "geometry/parts.h"

#include "geometry/lattice_source.h"

namespace lat {

void ShapeParts::part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
    if (parts_) return parts_->part_spheres(i, out);
    const auto* source = dynamic_cast<const LatticeSource*>(shape_);
    if (source && source->bounding_spheres(out)) return;
    const Bounds3 b = shape_->bounds();
    out.push_back({b.center(), 0.5 * length(b.extent())});
}

void ShapeSource::pieces_spans(std::span<const std::uint32_t> on, const Ray& r,
                               SpanList& out) const {
    if (pieces_) return pieces_->pieces_spans(on, r, out);
    const std::size_t first = out.size();
    for (const std::uint32_t i : on) parts_.part_spans(i, r, out);
    merge_span_union(out, first);
}

}  // namespace lat
