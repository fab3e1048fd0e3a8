#pragma once
// An exact lattice: the table (encoding `candidates`) names, per snapped pair, the pieces of the
// primitive (Pieces::piece_count) that a ray snapping to it can meet, and those are intersected
// exactly with the real ray. Images equal exact mode; the cost of a ray depends on how many
// pieces lie near it, not on how many the primitive has.
//
// A primitive that is the union of its pieces (a chain) has each listed piece intersected on
// its own. Otherwise (CSG: the pieces are its leaves) the primitive is evaluated with the
// unlisted pieces empty, which changes nothing along the ray's chord through the box: a
// piece is unlisted only when its solid keeps farther from the pair's segment than any ray
// snapping to it comes, and those rays' chords lie within kSnapReach of the segment. Outside
// the chord the primitive is empty, so spans that stay in the chord are the primitive's own;
// should one leave it (the pieces left on reach outside the box), the primitive answers whole.
#include <memory>

#include "geometry/lattice_source.h"
#include "geometry/parts.h"
#include "lattice/lattice_shape.h"
#include "lattice/part_boxes.h"

namespace lat {

class CandidateTableShape final : public Shape, public LatticeSource, public CullParts {
public:
    // ctx.primitive must be set and outlive the shape.
    CandidateTableShape(std::shared_ptr<const LatticeTable> table, const TableContext& ctx);

    Bounds3 bounds() const override { return frame_.box(); }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override {
        return primitive_->normal(r, c);
    }
    bool inside(Vec3 p) const override { return primitive_->inside(p); }
    // Crossings are the primitive's own: it names their surfaces and materials.
    std::uint32_t surface_count() const override { return source_.surface_count(); }
    bool names_surface(const Crossing& c) const override { return source_.names_surface(c); }
    bool cheap_normal(const Crossing& c) const override { return source_.cheap_normal(c); }
    // One table lookup, and the few pieces near the ray.
    double intersect_cost() const override { return 1.0; }
    std::size_t cull_count() const override { return frame_.cull_count(); }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double) const override {
        return frame_.cull_bounds(i, xf);
    }
    bool cull_meets(std::size_t i, const Ray& r) const override { return frame_.cull_meets(i, r); }
    bool cull_meets_any(const Ray& r) const override { return frame_.cull_meets_any(r); }
    bool cull_capsule(std::size_t i, const Transform& xf, double, Capsule& out) const override {
        return frame_.cull_capsule(i, xf, out);
    }

private:
    std::shared_ptr<const LatticeTable> table_;
    const Shape* primitive_;
    ShapeSource source_;  // the primitive's
    LatticeFrame frame_;
    PartBoxes boxes_;  // rejects candidates whose box the ray misses (lattice/part_boxes.h)

    bool union_;  // source_.pieces_are_union()

    // The pieces the ray can meet, and the ray's chord through the box; false when none.
    bool candidates(const Ray& r, CandidateList& list, LatticeFrame::Snap& s) const;
    // Not union_: the primitive's spans along r's line from the listed pieces alone; false
    // when one leaves the chord (they are then not the primitive's own).
    bool listed_spans(const Ray& r, const CandidateList& list, const LatticeFrame::Snap& s,
                      SpanList& out) const;
    // Not union_: the first crossing in (tmin, tmax), from the listed pieces or else whole.
    bool tree_crossing(const Ray& r, const CandidateList& list, const LatticeFrame::Snap& s,
                       double tmin, double tmax, Crossing& hit) const;
};

}  // namespace lat
