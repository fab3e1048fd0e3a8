#include "lattice/lattice_shape.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "lattice/candidate_table_shape.h"
#include "lattice/hit_table_shape.h"

namespace lat {
namespace {
thread_local std::uint64_t t_visits = 0;
}  // namespace

std::uint64_t lattice_visits_this_thread() {
    return t_visits;
}

LatticeFrame::LatticeFrame(const TableContext& ctx, double reach)
    : grid_(ctx.cells),
      cell_(ctx.cell),
      inv_cell_(1.0 / ctx.cell),
      box_{{0, 0, 0},
           Vec3{double(ctx.cells[0]), double(ctx.cells[1]), double(ctx.cells[2])} * ctx.cell} {
    if (!make_cull_capsules(ctx.primitive, reach)) make_cull_boxes(ctx.primitive, reach);
}

// Every answer's ray point lies within the reach of the primitive, so rays whose lines keep
// farther than that from every part lose nothing (images are identical). A capsule around
// each part grown by the reach tests that with a few dot products, before any snapping, and
// rejects most of the rays that only graze a part's box: on the fur plates four in five rays
// that met the boxes found no stored hit.
bool LatticeFrame::make_cull_capsules(const Shape* primitive, double reach) {
    if (!primitive || !std::isfinite(reach)) return false;
    std::vector<Capsule> capsules;
    std::vector<Bounds3> boxes;
    for (std::size_t i = 0; i < primitive->primitive_count(); ++i) {
        Capsule c;
        if (!primitive->primitive_capsule(i, c)) return false;
        c.r += reach;
        const Bounds3 b = lat::intersect(c.placed_bounds(Transform{}), box_);
        if (b.empty()) continue;
        capsules.push_back(c);
        boxes.push_back(b);
    }
    if (boxes.empty()) return false;  // nothing in the box: make_cull_boxes says so
    // A chain's joint sphere lies inside its cylinders' grown capsules: every culling part
    // costs a callback per ray that meets its box, so parts inside another are dropped (of
    // equal ones, the first is kept). Rounding in the test is far inside kSnapReach's slack.
    for (std::size_t i = 0; i < capsules.size(); ++i) {
        bool covered = false;
        for (std::size_t j = 0; j < capsules.size() && !covered; ++j)
            covered = j != i && capsules[j].contains(capsules[i]) &&
                      (j < i || !capsules[i].contains(capsules[j]));
        if (!covered) {
            capsules_.push_back(capsules[i]);
            cull_.push_back(boxes[i]);
        }
    }
    return true;
}

Bounds3 LatticeFrame::cull_bounds(std::size_t i, const Transform& xf) const {
    const Bounds3 clipped = xf.bounds(cull_[i]);
    return capsules_.empty() ? clipped : lat::intersect(clipped, capsules_[i].placed_bounds(xf));
}

// Without a grown primitive: boxes around the primitive's parts grown by the reach. Parts are
// grouped along the box's longest axis into a few boxes: fewer boxes than parts keep the
// accelerator small, and each is far tighter than the lattice box.
void LatticeFrame::make_cull_boxes(const Shape* primitive, double reach) {
    const std::size_t n = primitive ? primitive->primitive_count() : 0;
    if (!std::isfinite(reach) || n == 0) {
        cull_.push_back(box_);
        return;
    }
    const double grow = reach;
    struct Part {
        Bounds3 b;
        double key;
    };
    const Vec3 ext = box_.extent();
    const std::size_t axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    std::vector<Part> parts;
    for (std::size_t i = 0; i < n; ++i) {
        const Bounds3 b = lat::intersect(expand(primitive->primitive_bounds(i), grow), box_);
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

bool LatticeFrame::snap(const Ray& r, Snap& s) const {
    ++t_visits;
    s.o = r.o * inv_cell_;
    s.d = r.d * inv_cell_;
    const Vec3 o = s.o, d = s.d;
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
    s.pa = on_face(t0, ax0, d[static_cast<std::size_t>(ax0)] < 0);
    s.pb = on_face(t1, ax1, d[static_cast<std::size_t>(ax1)] > 0);
    s.a = grid_.id(s.pa);
    s.b = grid_.id(s.pb);
    return true;
}

std::shared_ptr<const Shape> make_lattice_shape(std::shared_ptr<const LatticeTable> table,
                                                const TableContext& ctx, double hit_error) {
    assert(ctx.primitive);
    if (table->kind() == LatticeTable::Kind::kCandidates)
        return std::make_shared<CandidateTableShape>(std::move(table), ctx);
    // Snapping moves each end of the ray's chord through the box by at most kSnapReach cells,
    // so every point of the snapped segment lies within that of the chord point with the same
    // parameter. A stored hit is on the snapped segment and within hit_error of the primitive,
    // and the answer's ray parameter is its projection on the ray: the ray point there lies
    // within kSnapReach cells + hit_error of the primitive.
    const double reach = ctx.cell * kSnapReach + hit_error;
    return std::make_shared<HitTableShape>(std::move(table), ctx, reach);
}

}  // namespace lat
