#pragma once
// An exact lattice: the table (encoding `candidates`) names, per snapped pair, the parts of the
// primitive that a ray snapping to it can meet, and those are intersected exactly with the
// real ray. Images equal exact mode; the cost of a ray depends on how many parts lie near it,
// not on how many the primitive has.
#include <memory>

#include "lattice/lattice_shape.h"
#include "lattice/part_boxes.h"

namespace lat {

class CandidateTableShape final : public Shape {
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
    std::size_t cull_count() const override { return frame_.cull_count(); }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf) const override {
        return frame_.cull_bounds(i, xf);
    }
    bool cull_meets(std::size_t i, const Ray& r) const override { return frame_.cull_meets(i, r); }

private:
    std::shared_ptr<const LatticeTable> table_;
    const Shape* primitive_;
    LatticeFrame frame_;
    PartBoxes boxes_;  // rejects candidates whose box the ray misses (lattice/part_boxes.h)

    // The parts the ray can meet; false when none.
    bool candidates(const Ray& r, CandidateList& list) const;
};

}  // namespace lat
