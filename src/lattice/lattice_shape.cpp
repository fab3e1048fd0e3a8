#include "lattice/lattice_shape.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <vector>

namespace lat {

LatticeShape::LatticeShape(std::shared_ptr<const LatticeTable> table, std::array<int, 3> cells,
                           double cell, const Shape* primitive, double hit_error)
    : table_(std::move(table)),
      grid_(cells),
      cell_(cell),
      inv_cell_(1.0 / cell),
      box_{{0, 0, 0}, Vec3{double(cells[0]), double(cells[1]), double(cells[2])} * cell},
      primitive_(primitive),
      exact_(table_->kind() == LatticeTable::Kind::kCandidates) {
    assert(!exact_ || primitive_);
    make_cull_boxes(exact_ ? 0.0 : hit_error);
}

// Snapping moves each end of the ray's chord through the box by at most sqrt(2)/2 cells (two
// coordinates rounded on a face), so every point of the snapped segment lies within that of
// the chord point with the same parameter. A stored hit is on the snapped segment and within
// hit_error of the primitive, and the answer's ray parameter is its projection on the ray: the
// ray point there lies within sqrt(2)/2 cells + hit_error of the primitive. Boxes around the
// primitive's parts grown by that much therefore contain every answer, and rays that miss them
// lose nothing (images are identical). Parts are grouped along the box's longest axis into a few
// boxes: fewer boxes than parts keep the accelerator small, and each is far tighter than the
// lattice box.
void LatticeShape::make_cull_boxes(double hit_error) {
    const std::size_t n = primitive_ ? primitive_->primitive_count() : 0;
    if (!primitive_ || !std::isfinite(hit_error) || n == 0) {
        cull_.push_back(box_);
        return;
    }
    const double grow = cell_ * (std::sqrt(0.5) + 1e-6) + hit_error;
    struct Part {
        Bounds3 b;
        double key;
    };
    const Vec3 ext = box_.extent();
    const std::size_t axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    std::vector<Part> parts;
    for (std::size_t i = 0; i < n; ++i) {
        const Bounds3 b = lat::intersect(expand(primitive_->primitive_bounds(i), grow), box_);
        if (!b.empty()) parts.push_back({b, b.center()[axis]});
    }
    if (parts.empty()) {  // nothing in the box: nothing to hit (the table is empty)
        cull_.push_back(Bounds3{});
        return;
    }
    std::stable_sort(parts.begin(), parts.end(),
                     [](const Part& a, const Part& b) { return a.key < b.key; });
    // Two neighbouring parts a box (for a chain, a sphere and its cylinder) was fastest on the
    // plates among 1, 3, 6, 10 and 19 boxes for the 19-part hair.
    const std::size_t groups = std::min<std::size_t>((parts.size() + 1) / 2, 16);
    auto volume = [](const Bounds3& b) { return b.extent().x * b.extent().y * b.extent().z; };
    double total = 0;
    for (std::size_t g = 0; g < groups; ++g) {
        Bounds3 b;
        for (std::size_t i = g * parts.size() / groups; i < (g + 1) * parts.size() / groups; ++i)
            b = merge(b, parts[i].b);
        cull_.push_back(b);
        total += volume(b);
    }
    // A primitive that fills its box (a thin spike) gains nothing from several boxes.
    if (total >= volume(box_)) cull_.assign(1, box_);
}

void LatticeShape::cull_boxes(std::vector<Bounds3>& out) const {
    out.insert(out.end(), cull_.begin(), cull_.end());
}

bool LatticeShape::snap(const Ray& r, std::uint32_t& a, std::uint32_t& b, GridPoint& pa,
                        GridPoint& pb) const {
    const Vec3 o = r.o * inv_cell_, d = r.d * inv_cell_;
    const auto& n = grid_.cells();
    double t0 = -kInfinity, t1 = kInfinity;
    int ax0 = -1, ax1 = -1;
    for (int k = 0; k < 3; ++k) {
        const auto uk = static_cast<std::size_t>(k);
        if (d[uk] == 0) {
            if (o[uk] < 0 || o[uk] > n[uk]) return false;
            continue;
        }
        const double inv = 1.0 / d[uk];
        double tn = -o[uk] * inv, tf = (n[uk] - o[uk]) * inv;
        if (tn > tf) std::swap(tn, tf);
        if (tn > t0) t0 = tn, ax0 = k;
        if (tf < t1) t1 = tf, ax1 = k;
    }
    if (!(t0 <= t1) || ax0 < 0 || ax1 < 0) return false;
    // Round the entry and exit points to the nearest grid points on their faces.
    auto on_face = [&](double t, int axis, bool high) {
        GridPoint g;
        const Vec3 x = o + d * t;
        for (int k = 0; k < 3; ++k) {
            const auto uk = static_cast<std::size_t>(k);
            g[k] = k == axis
                       ? (high ? n[uk] : 0)
                       : static_cast<int>(std::clamp(std::nearbyint(x[uk]), 0.0, double(n[uk])));
        }
        return g;
    };
    pa = on_face(t0, ax0, d[static_cast<std::size_t>(ax0)] < 0);
    pb = on_face(t1, ax1, d[static_cast<std::size_t>(ax1)] > 0);
    a = grid_.id(pa);
    b = grid_.id(pb);
    return a != b || exact_;
}

bool LatticeShape::candidates(const Ray& r, CandidateList& list) const {
    std::uint32_t a, b;
    GridPoint pa, pb;
    return snap(r, a, b, pa, pb) && table_->candidates(a, b, list);
}

namespace {

Vec3 to_vec(const GridPoint& g) {
    return {double(g.x), double(g.y), double(g.z)};
}

}  // namespace

LatticeShape::LineHits LatticeShape::line_hits(const Ray& r, double need_last_below) const {
    LineHits lh;
    std::uint32_t a, b;
    GridPoint pa, pb;
    if (!snap(r, a, b, pa, pb)) return lh;
    TableHit fwd, rev;
    if (!table_->lookup(a, b, fwd)) return lh;
    const Vec3 va = to_vec(pa), vb = to_vec(pb);
    const Vec3 o = r.o * inv_cell_, d = r.d * inv_cell_;
    const double dd = dot(d, d);
    const Vec3 pf = lerp(va, vb, fwd.t);
    lh.hit = true;
    lh.t_first = dot(pf - o, d) / dd;
    lh.p_first = pf * cell_;
    lh.n_first = fwd.normal;
    if (lh.t_first > need_last_below) {  // callers only ask whether the last lies past the first
        lh.t_last = lh.t_first;
        return lh;
    }
    if (table_->lookup(b, a, rev)) {
        const Vec3 pl = lerp(vb, va, rev.t);
        lh.t_last = std::max(lh.t_first, dot(pl - o, d) / dd);
        lh.p_last = pl * cell_;
        lh.n_last = rev.normal;
    } else {  // only from a table built with a different closed-ness convention
        lh.t_last = lh.t_first;
        lh.p_last = lh.p_first;
        lh.n_last = -lh.n_first;
    }
    return lh;
}

bool LatticeShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    if (exact_) {
        CandidateList list;
        if (!candidates(r, list)) return false;
        bool found = false;
        for (int k = 0; k < list.count; ++k)
            if (primitive_->intersect_primitive(list.parts[k], r, tmin, tmax, hit)) {
                tmax = hit.t;
                found = true;
            }
        return found;
    }
    const LineHits lh = line_hits(r, tmin);
    if (!lh.hit) return false;
    if (lh.t_first > tmin && lh.t_first < tmax) {
        hit = {lh.t_first, 0, 0};
        return true;
    }
    if (lh.t_last > tmin && lh.t_last < tmax) {
        hit = {lh.t_last, 1, 0};
        return true;
    }
    return false;
}

bool LatticeShape::occluded(const Ray& r, double tmin, double tmax) const {
    if (exact_) {
        CandidateList list;
        if (!candidates(r, list)) return false;
        for (int k = 0; k < list.count; ++k)
            if (primitive_->occluded_primitive(list.parts[k], r, tmin, tmax)) return true;
        return false;
    }
    // The table knows the line's first and last crossings; between them it counts as solid.
    const LineHits lh = line_hits(r, tmin);
    return lh.hit && (lh.t_first > tmin || lh.t_last > tmin) && lh.t_first < tmax;
}

void LatticeShape::spans(const Ray& r, SpanList& out) const {
    if (exact_) {  // the union of the candidate parts' spans
        CandidateList list;
        if (!candidates(r, list)) return;
        const std::size_t first = out.size();
        for (int k = 0; k < list.count; ++k) primitive_->primitive_spans(list.parts[k], r, out);
        merge_span_union(out, first);
        return;
    }
    const LineHits lh = line_hits(r);
    if (lh.hit && lh.t_first < lh.t_last) out.push_back({{lh.t_first, 0, 0}, {lh.t_last, 1, 0}});
}

Vec3 LatticeShape::normal(const Ray& r, const Crossing& c) const {
    if (exact_) return primitive_->normal(r, c);
    const LineHits lh = line_hits(r);
    return c.part == 0 ? lh.n_first : lh.n_last;
}

Vec3 LatticeShape::position(const Ray& r, const Crossing& c) const {
    if (exact_) return r.at(c.t);
    const LineHits lh = line_hits(r);
    return c.part == 0 ? lh.p_first : lh.p_last;
}

bool LatticeShape::inside(Vec3 p) const {
    // As the table sees it: p lies between the first and last crossing of the vertical line.
    const LineHits lh = line_hits({p, {0, 0, 1}});
    return lh.hit && lh.t_first <= 0 && lh.t_last >= 0;
}

}  // namespace lat
