#include "lattice/candidate_table_shape.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lat {
namespace {

// A ray's slab test against boxes, its reciprocals computed once a visit.
struct Slabs {
    Vec3 o, inv;
    bool flat[3];  // direction component 0: the ray stays in its plane
    explicit Slabs(const Ray& r) : o(r.o) {
        for (std::size_t k = 0; k < 3; ++k) {
            flat[k] = r.d[k] == 0;
            inv[k] = flat[k] ? 0.0 : 1.0 / r.d[k];
        }
    }
    // Whether the ray's line meets b at some t in [tmin, tmax].
    bool meets(const Bounds3& b, double tmin, double tmax) const {
        for (std::size_t k = 0; k < 3; ++k) {
            if (flat[k]) {
                if (o[k] < b.lo[k] || o[k] > b.hi[k]) return false;
                continue;
            }
            const double t0 = (b.lo[k] - o[k]) * inv[k], t1 = (b.hi[k] - o[k]) * inv[k];
            tmin = std::max(tmin, std::min(t0, t1));
            tmax = std::min(tmax, std::max(t0, t1));
        }
        return tmin <= tmax;
    }
};

// The part's box grown far beyond rounding (of the slab test, and of crossings that count as
// touching with kTouchTolerance), so that no crossing a part reports lies outside it.
Bounds3 padded(const Bounds3& b) {
    const double scale = max_component(abs(b.lo)) + max_component(abs(b.hi)) + length(b.extent());
    return expand(b, 1e-6 * scale + 1e-12);
}

}  // namespace

CandidateTableShape::CandidateTableShape(std::shared_ptr<const LatticeTable> table,
                                         const TableContext& ctx)
    : table_(std::move(table)), primitive_(ctx.primitive), frame_(ctx, 0.0) {
    assert(primitive_ && table_->kind() == LatticeTable::Kind::kCandidates);
    part_boxes_.reserve(primitive_->primitive_count());
    for (std::size_t i = 0; i < primitive_->primitive_count(); ++i)
        part_boxes_.push_back(padded(primitive_->primitive_bounds(i)));
}

void CandidateTableShape::cull_boxes(std::vector<Bounds3>& out) const {
    out.insert(out.end(), frame_.cull_boxes().begin(), frame_.cull_boxes().end());
}

bool CandidateTableShape::candidates(const Ray& r, CandidateList& list) const {
    LatticeFrame::Snap s;
    return frame_.snap(r, s) && table_->candidates(s.a, s.b, list);
}

bool CandidateTableShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    CandidateList list;
    if (!candidates(r, list)) return false;
    const Slabs slabs(r);
    bool found = false;
    for (int k = 0; k < list.count; ++k) {
        const std::uint32_t part = list.parts[k];
        if (!slabs.meets(part_boxes_[part], tmin, tmax)) continue;
        if (primitive_->intersect_primitive(part, r, tmin, tmax, hit)) {
            tmax = hit.t;
            found = true;
        }
    }
    return found;
}

bool CandidateTableShape::occluded(const Ray& r, double tmin, double tmax) const {
    CandidateList list;
    if (!candidates(r, list)) return false;
    const Slabs slabs(r);
    for (int k = 0; k < list.count; ++k) {
        const std::uint32_t part = list.parts[k];
        if (slabs.meets(part_boxes_[part], tmin, tmax) &&
            primitive_->occluded_primitive(part, r, tmin, tmax))
            return true;
    }
    return false;
}

void CandidateTableShape::spans(const Ray& r, SpanList& out) const {
    CandidateList list;
    if (!candidates(r, list)) return;
    const std::size_t first = out.size();
    const Slabs slabs(r);
    for (int k = 0; k < list.count; ++k)
        if (slabs.meets(part_boxes_[list.parts[k]], -kInfinity, kInfinity))
            primitive_->primitive_spans(list.parts[k], r, out);
    merge_span_union(out, first);  // the union of the candidate parts' spans
}

}  // namespace lat
