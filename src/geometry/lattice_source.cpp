#include "geometry/lattice_source.h"

namespace lat {

void ShapeSource::pieces_spans(std::span<const std::uint32_t> on, const Ray& r,
                               SpanList& out) const {
    if (pieces_) return pieces_->pieces_spans(on, r, out);
    const std::size_t first = out.size();
    for (const std::uint32_t i : on) parts_.part_spans(i, r, out);
    merge_span_union(out, first);
}

}  // namespace lat
