#include "lattice/hit_table_shape.h"

#include <algorithm>

namespace lat {

HitTableShape::HitTableShape(std::shared_ptr<const LatticeTable> table, const TableContext& ctx,
                             double reach)
    : table_(std::move(table)), frame_(ctx, reach) {}

bool HitTableShape::line_hits(const Ray& r, LineHits& lh, double need_last_below) const {
    LatticeFrame::Snap s;
    if (!frame_.snap(r, s) || s.a == s.b) return false;
    TableHit fwd, rev;
    if (!table_->lookup(s.a, s.b, fwd)) return false;
    const Vec3 va = to_vec(s.pa), vb = to_vec(s.pb);
    const double dd = dot(s.d, s.d);
    const double cell = frame_.cell();
    const Vec3 pf = lerp(va, vb, fwd.t);
    lh.first = {dot(pf - s.o, s.d) / dd, 0, SurfacePoint{pf * cell, fwd.normal}};
    lh.last = lh.first;
    if (lh.first.t > need_last_below) return true;
    lh.last.part = 1;
    if (table_->lookup(s.b, s.a, rev)) {
        const Vec3 pl = lerp(vb, va, rev.t);
        lh.last.t = std::max(lh.first.t, dot(pl - s.o, s.d) / dd);
        lh.last.stored = {pl * cell, rev.normal};
    } else {  // only from a table built with a different closed-ness convention
        lh.last.stored.n = -lh.first.stored.n;
    }
    return true;
}

bool HitTableShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    LineHits lh;
    if (!line_hits(r, lh, tmin)) return false;
    for (const Crossing& c : {lh.first, lh.last})
        if (c.t > tmin && c.t < tmax) {
            hit = c;
            return true;
        }
    return false;
}

bool HitTableShape::occluded(const Ray& r, double tmin, double tmax) const {
    // The table knows the line's first and last crossings; between them it counts as solid.
    // As line_hits, with t alone (no normals).
    LatticeFrame::Snap s;
    if (!frame_.snap(r, s) || s.a == s.b) return false;
    double fwd = 0, rev = 0;
    if (!table_->lookup_t(s.a, s.b, fwd)) return false;
    const Vec3 va = to_vec(s.pa), vb = to_vec(s.pb);
    const double dd = dot(s.d, s.d);
    const double first = dot(lerp(va, vb, fwd) - s.o, s.d) / dd;
    if (first >= tmax) return false;
    if (first > tmin) return true;
    // The last crossing; without a reverse hit (a table of another closed-ness convention)
    // it is the first.
    const double last = table_->lookup_t(s.b, s.a, rev)
                            ? std::max(first, dot(lerp(vb, va, rev) - s.o, s.d) / dd)
                            : first;
    return last > tmin;
}

void HitTableShape::spans(const Ray& r, SpanList& out) const {
    LineHits lh;
    if (line_hits(r, lh) && lh.first.t < lh.last.t) out.push_back({lh.first, lh.last});
}

bool HitTableShape::inside(Vec3 p) const {
    // As the table sees it: p lies between the first and last crossing of the vertical line.
    LineHits lh;
    return line_hits({p, {0, 0, 1}}, lh) && lh.first.t <= 0 && lh.last.t >= 0;
}

}  // namespace lat
