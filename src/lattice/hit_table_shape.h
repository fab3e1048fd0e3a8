#pragma once
// A lattice whose table stores each pair's hit (every encoding but `candidates`). The stored
// point (near, not on, the ray) is the hit's position and travels in the crossing with its
// normal, so the one lookup that finds a hit also shades it; its projection on the ray orders
// it against other objects. The reverse pair (p_o, p_i) gives the last crossing, so a lattice
// is also a CSG leaf (one span per ray) and shadows itself.
#include <memory>

#include "geometry/parts.h"
#include "lattice/lattice_shape.h"

namespace lat {

class HitTableShape final : public Shape, public CullParts {
public:
    HitTableShape(std::shared_ptr<const LatticeTable> table, const TableContext& ctx,
                  double reach);

    Bounds3 bounds() const override { return frame_.box(); }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    // Crossings of this shape always carry their stored point and normal.
    Vec3 normal(const Ray&, const Crossing& c) const override { return c.stored.n; }
    bool inside(Vec3 p) const override;
    std::size_t cull_count() const override { return frame_.cull_count(); }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double) const override {
        return frame_.cull_bounds(i, xf);
    }
    bool cull_meets(std::size_t i, const Ray& r) const override { return frame_.cull_meets(i, r); }
    bool cull_meets_any(const Ray& r) const override { return frame_.cull_meets_any(r); }
    bool cull_capsule(std::size_t i, const Transform& xf, double, Capsule& out) const override {
        return frame_.cull_capsule(i, xf, out);
    }
    // Rays leaving a point found through this lattice skip crossings within this distance of
    // it: the table's own error, which would otherwise shade the surface by itself (acne).
    double surface_tolerance() const override { return 2.0 * frame_.cell(); }

private:
    std::shared_ptr<const LatticeTable> table_;
    LatticeFrame frame_;

    // The first and last crossings of the ray's line, with their stored surface points.
    struct LineHits {
        Crossing first, last;
    };
    // False when the line misses. The last crossing is only looked up when the first is at or
    // before need_last_below (else last = first: callers only ask whether it lies beyond).
    bool line_hits(const Ray& r, LineHits& lh, double need_last_below = kInfinity) const;
};

}  // namespace lat
