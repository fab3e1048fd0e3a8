#pragma once
// A lattice instance's shape (paper 2.1, 3.2.2): rays are answered by the table, not by the
// primitive. In the primitive's coordinates the ray is scaled to lattice units, clipped to the
// box, its entry and exit points are rounded to the nearest grid points on their faces, and
// the pair is looked up. The stored point (near, not on, the ray) is the hit's position; its
// projection on the ray orders it against other objects. The reverse pair (p_o, p_i) gives
// the last crossing, so a lattice is also a CSG leaf (one span per ray) and shadows itself.
// With a candidate table (encoding `candidates`) the pair instead names the primitive's parts
// the ray can meet, and those are intersected exactly with the real ray: an exact lattice.
#include <memory>

#include "geometry/shape.h"
#include "lattice/boundary_grid.h"
#include "lattice/table.h"

namespace lat {

class LatticeShape final : public Shape {
public:
    // cells: the lattice at its refinement; cell: the cell size in primitive units; the
    // primitive is needed by candidate tables and for culling (kept alive by the caller);
    // hit_error: how far a stored hit can lie from the primitive (hit_error_bound), infinity
    // when unknown, which culls with the lattice box alone.
    LatticeShape(std::shared_ptr<const LatticeTable> table, std::array<int, 3> cells, double cell,
                 const Shape* primitive = nullptr, double hit_error = kInfinity);

    const LatticeTable& table() const { return *table_; }

    Bounds3 bounds() const override { return box_; }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override;
    Vec3 position(const Ray& r, const Crossing& c) const override;
    bool inside(Vec3 p) const override;
    void cull_boxes(std::vector<Bounds3>& out) const override;
    // Rays leaving a point found through this lattice skip crossings within this distance of
    // it: the table's own error, which would otherwise shade the surface by itself (acne).
    // Exact (candidate) lattices need none.
    double surface_tolerance() const override { return exact_ ? 0.0 : 2.0 * cell_; }

    // The two crossings of the ray's line (first and last), as ray parameters and points.
    struct LineHits {
        bool hit = false;
        double t_first = 0, t_last = 0;
        Vec3 p_first, p_last;  // primitive units
        Vec3 n_first, n_last;
    };
    // The last crossing is only looked up when the first is at or before need_last_below
    // (else t_last = t_first and p_last, n_last are unset).
    LineHits line_hits(const Ray& r, double need_last_below = kInfinity) const;

private:
    std::shared_ptr<const LatticeTable> table_;
    BoundaryGrid grid_;
    double cell_, inv_cell_;
    Bounds3 box_;  // primitive units

    const Shape* primitive_;
    bool exact_;                 // a candidate table
    std::vector<Bounds3> cull_;  // see make_cull_boxes

    // Snapped entry and exit point ids of the ray's line; false if it misses the box (or, for
    // hit tables, when both snap to the same point).
    bool snap(const Ray& r, std::uint32_t& a, std::uint32_t& b, GridPoint& pa, GridPoint& pb) const;
    // A few boxes around the primitive grown by the snapping distance and the table's error:
    // no ray outside them can get a hit (see lattice_shape.cpp).
    void make_cull_boxes(double hit_error);
    // Candidate tables: the parts the ray can meet; false when none.
    bool candidates(const Ray& r, CandidateList& list) const;
};

}  // namespace lat
