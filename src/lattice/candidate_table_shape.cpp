#include "lattice/candidate_table_shape.h"

#include <cassert>

#include "geometry/scratch_spans.h"

namespace lat {

CandidateTableShape::CandidateTableShape(std::shared_ptr<const LatticeTable> table,
                                         const TableContext& ctx)
    : table_(std::move(table)),
      primitive_(ctx.primitive),
      source_(*ctx.primitive),
      frame_(ctx, 0.0),  // answers are the primitive's own crossings
      boxes_(source_.parts(), frame_.box()),
      union_(source_.pieces_are_union()) {
    assert(primitive_ && table_->kind() == LatticeTable::Kind::kCandidates);
}

bool CandidateTableShape::candidates(const Ray& r, CandidateList& list,
                                     LatticeFrame::Snap& s) const {
    return frame_.snap(r, s) && table_->candidates(s.a, s.b, list);
}

bool CandidateTableShape::listed_spans(const Ray& r, const CandidateList& list,
                                       const LatticeFrame::Snap& s, SpanList& out) const {
    const std::size_t first = out.size();
    source_.pieces_spans(list.span(), r, out);
    if (out.size() == first) return true;  // no spans: no chord to keep them in
    LatticeFrame::Chord c;
    if (!frame_.chord(s.o, s.d, c)) return false;
    for (std::size_t k = first; k < out.size(); ++k)
        if (!(out[k].in.t >= c.t0 && out[k].out.t <= c.t1)) return false;
    return true;
}

bool CandidateTableShape::tree_crossing(const Ray& r, const CandidateList& list,
                                        const LatticeFrame::Snap& s, double tmin, double tmax,
                                        Crossing& hit) const {
    ScratchSpans spans;
    if (!listed_spans(r, list, s, *spans)) return primitive_->intersect(r, tmin, tmax, hit);
    return first_crossing(*spans, tmin, tmax, hit);
}

bool CandidateTableShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    CandidateList list;
    LatticeFrame::Snap s;
    if (!candidates(r, list, s)) return false;
    if (!union_) return tree_crossing(r, list, s, tmin, tmax, hit);
    return boxes_.first_crossing(source_.parts(), list.span(), r, tmin, tmax, hit);
}

bool CandidateTableShape::occluded(const Ray& r, double tmin, double tmax) const {
    CandidateList list;
    LatticeFrame::Snap s;
    if (!candidates(r, list, s)) return false;
    if (!union_) {
        Crossing c;  // a tree's occlusion is its first crossing (CsgShape has no cheaper one)
        return tree_crossing(r, list, s, tmin, tmax, c);
    }
    return boxes_.any_occludes(source_.parts(), list.span(), r, tmin, tmax);
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
    slabs.any_listed(list.span(), range, [&](std::uint32_t part) {
        source_.parts().part_spans(part, r, out);
        return false;
    });
    merge_span_union(out, first);  // the union of the candidate parts' spans
}

}  // namespace lat
