#include "lattice/candidate_table_shape.h"

#include <cassert>
#include <deque>

namespace lat {
namespace {

// A span list per nesting level (a lattice leaf of a CSG primitive of a lattice), so that a
// visit allocates nothing once warm and a nested visit does not reuse its caller's list.
class ScratchSpans {
public:
    ScratchSpans() : list_(level(depth_++)) { list_.clear(); }
    ~ScratchSpans() { --depth_; }
    ScratchSpans(const ScratchSpans&) = delete;
    ScratchSpans& operator=(const ScratchSpans&) = delete;
    SpanList& get() { return list_; }

private:
    static SpanList& level(std::size_t i) {
        thread_local std::deque<SpanList> pool;  // a deque: growing it keeps references valid
        if (pool.size() <= i) pool.resize(i + 1);
        return pool[i];
    }
    static thread_local std::size_t depth_;
    SpanList& list_;
};
thread_local std::size_t ScratchSpans::depth_ = 0;

}  // namespace

CandidateTableShape::CandidateTableShape(std::shared_ptr<const LatticeTable> table,
                                         const TableContext& ctx)
    : table_(std::move(table)),
      primitive_(ctx.primitive),
      frame_(ctx, 0.0),  // answers are the primitive's own crossings
      boxes_(*ctx.primitive, frame_.box()),
      union_(ctx.primitive->pieces_are_union()) {
    assert(primitive_ && table_->kind() == LatticeTable::Kind::kCandidates);
}

bool CandidateTableShape::candidates(const Ray& r, CandidateList& list,
                                     LatticeFrame::Snap& s) const {
    return frame_.snap(r, s) && table_->candidates(s.a, s.b, list);
}

bool CandidateTableShape::listed_spans(const Ray& r, const CandidateList& list,
                                       const LatticeFrame::Snap& s, SpanList& out) const {
    const std::size_t first = out.size();
    primitive_->pieces_spans({list.parts, static_cast<std::size_t>(list.count)}, r, out);
    for (std::size_t k = first; k < out.size(); ++k)
        if (!(out[k].in.t >= s.t0 && out[k].out.t <= s.t1)) return false;
    return true;
}

bool CandidateTableShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    CandidateList list;
    LatticeFrame::Snap s;
    if (!candidates(r, list, s)) return false;
    if (!union_) {
        ScratchSpans spans;
        if (!listed_spans(r, list, s, spans.get()))
            return primitive_->intersect(r, tmin, tmax, hit);
        return first_crossing(spans.get(), tmin, tmax, hit);
    }
    const PartBoxes::Ray4 slabs(boxes_, r);
    PartBoxes::Ray4::Range range = slabs.range(tmin, tmax);
    bool found = false;
    for (int k = 0; k < list.count; ++k) {
        const std::uint32_t part = list.parts[k];
        if (!slabs.meets(part, range)) continue;
        if (primitive_->intersect_primitive(part, r, tmin, tmax, hit)) {
            tmax = hit.t;
            range = slabs.range(tmin, tmax);
            found = true;
        }
    }
    return found;
}

bool CandidateTableShape::occluded(const Ray& r, double tmin, double tmax) const {
    CandidateList list;
    LatticeFrame::Snap s;
    if (!candidates(r, list, s)) return false;
    if (!union_) {
        ScratchSpans spans;
        if (!listed_spans(r, list, s, spans.get())) return primitive_->occluded(r, tmin, tmax);
        Crossing c;
        return first_crossing(spans.get(), tmin, tmax, c);
    }
    const PartBoxes::Ray4 slabs(boxes_, r);
    const PartBoxes::Ray4::Range range = slabs.range(tmin, tmax);
    for (int k = 0; k < list.count; ++k) {
        const std::uint32_t part = list.parts[k];
        if (slabs.meets(part, range) && primitive_->occluded_primitive(part, r, tmin, tmax))
            return true;
    }
    return false;
}

void CandidateTableShape::spans(const Ray& r, SpanList& out) const {
    CandidateList list;
    LatticeFrame::Snap s;
    if (!candidates(r, list, s)) return;
    const std::size_t first = out.size();
    if (!union_) {
        if (!listed_spans(r, list, s, out)) {
            out.resize(first);
            primitive_->spans(r, out);
        }
        return;
    }
    const PartBoxes::Ray4 slabs(boxes_, r);
    const PartBoxes::Ray4::Range range = slabs.range(-kInfinity, kInfinity);
    for (int k = 0; k < list.count; ++k)
        if (slabs.meets(list.parts[k], range)) primitive_->primitive_spans(list.parts[k], r, out);
    merge_span_union(out, first);  // the union of the candidate parts' spans
}

}  // namespace lat
