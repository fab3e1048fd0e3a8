#include "lattice/lattice_shape.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

#include "lattice/candidate_table_shape.h"
#include "lattice/float_snap.h"
#include "lattice/hit_table_shape.h"
#include "util/stats.h"

namespace lat {

LatticeFrame::LatticeFrame(const TableContext& ctx, double reach, double beyond_box)
    : grid_(ctx.cells),
      cell_(ctx.cell),
      inv_cell_(1.0 / ctx.cell),
      box_{{0, 0, 0},
           Vec3{double(ctx.cells[0]), double(ctx.cells[1]), double(ctx.cells[2])} * ctx.cell} {
    make_cull_parts(ctx.primitive, reach, expand(box_, beyond_box));
    if (std::all_of(cull_.begin(), cull_.end(), [](const CullPart& p) { return p.count > 0; }))
        screen_ = CapsuleScreen(capsules_);
    if (std::isfinite(reach) && beyond_box >= reach) max_narrower_ = reach;
}

// Every answer's ray point lies within the reach of the primitive (make_lattice_shape), so
// rays whose lines keep farther than that from every part lose nothing (images are
// identical). The accelerator culls with boxes around the parts grown by the reach, grouped
// along the box's longest axis into at most kMaxCullParts (fewer boxes than parts keep the
// accelerator small, and each is far tighter than the lattice box). When the parts are a few
// capsules (a hair), each is a cull part of its own and its capsule grown by the reach is
// tested too, a few dot products before any snapping: on the fur plates four in five rays
// that met the boxes found no stored hit.
void LatticeFrame::make_cull_parts(const Shape* primitive, double reach, const Bounds3& region) {
    if (!primitive) {
        cull_.push_back({region, 0, 0});
        return;
    }
    const ShapeParts parts(*primitive);
    const std::size_t n = parts.part_count();
    if (!std::isfinite(reach) || n == 0) {
        cull_.push_back({region, 0, 0});
        return;
    }
    const Vec3 ext = box_.extent();
    const std::size_t axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    std::vector<CulledPart> pieces;
    bool capsules = true;
    for (std::size_t i = 0; i < n; ++i) {
        CulledPart p;
        p.part = static_cast<std::uint32_t>(i);
        p.box = lat::intersect(expand(parts.part_bounds(i), reach), region);
        capsules = capsules && parts.part_capsule(i, p.capsule);
        p.capsule.r += reach;
        if (!p.box.empty()) pieces.push_back(p);
    }
    if (pieces.empty()) {  // nothing in the box: nothing to hit (the table is empty)
        cull_.push_back({Bounds3{}, 0, 0});
        return;
    }
    std::vector<CulledPart> few;  // the capsules, if a few hold them all
    if (capsules && pieces.size() <= 4 * kMaxCullParts) {
        few = pieces;
        // A kept capsule stands for those it covers, so its box is its own (not its part's).
        for (CulledPart& p : few) p.box = lat::intersect(p.capsule.placed_bounds(Transform{}), region);
        drop_covered(few);
    }
    capsules = capsules && !few.empty() && few.size() <= kMaxCullParts;
    if (capsules) pieces = std::move(few);
    if (!capsules && n <= kMaxPlacedParts) {
        primitive_ = parts;
        reach_ = reach;
    }
    for (CulledPart& p : pieces) p.key = p.box.center()[axis];
    std::stable_sort(pieces.begin(), pieces.end(),
                     [](const CulledPart& a, const CulledPart& b) { return a.key < b.key; });
    group(pieces, capsules, region);
}

// A chain's joint sphere lies inside its cylinders' grown capsules: every culling part costs a
// callback per ray that meets its box, so pieces inside another are dropped (of equal ones, the
// first is kept). Quadratic: only for primitives of a few parts. Rounding in the test is far
// inside kSnapReach's slack.
void LatticeFrame::drop_covered(std::vector<CulledPart>& pieces) {
    std::vector<CulledPart> kept;
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        bool covered = false;
        for (std::size_t j = 0; j < pieces.size() && !covered; ++j)
            covered = j != i && pieces[j].capsule.contains(pieces[i].capsule) &&
                      (j < i || !pieces[i].capsule.contains(pieces[j].capsule));
        if (!covered) kept.push_back(pieces[i]);
    }
    pieces = std::move(kept);
}

void LatticeFrame::group(const std::vector<CulledPart>& pieces, bool capsules,
                         const Bounds3& region) {
    // Boxes alone: two neighbouring parts a box (for a chain, a sphere and its cylinder) was
    // fastest on the plates among 1, 3, 6, 10 and 19 boxes for the 19-part hair. Capsules pay
    // only one to a part: groups of them (tufts of 200 parts in 16 groups) cost 1.5x the
    // instructions of boxes alone, for fatter boxes and longer tests.
    const std::size_t groups =
        capsules ? pieces.size() : std::min((pieces.size() + 1) / 2, kMaxCullParts);
    auto volume = [](const Bounds3& b) { return b.extent().x * b.extent().y * b.extent().z; };
    double total = 0;
    bool tested = false;
    for (std::size_t g = 0; g < groups; ++g) {
        const std::size_t first = g * pieces.size() / groups, end = (g + 1) * pieces.size() / groups;
        CullPart part{{}, 0, 0};
        for (std::size_t i = first; i < end; ++i) part.box = merge(part.box, pieces[i].box);
        if (primitive_) {
            part.part_first = static_cast<std::uint32_t>(parts_.size());
            part.part_count = static_cast<std::uint32_t>(end - first);
            for (std::size_t i = first; i < end; ++i) parts_.push_back(pieces[i].part);
        }
        if (capsules) {
            part.first = static_cast<std::uint32_t>(capsules_.size());
            part.count = static_cast<std::uint32_t>(end - first);
            for (std::size_t i = first; i < end; ++i) capsules_.push_back(pieces[i].capsule);
            tested = true;
        }
        cull_.push_back(part);
        total += volume(part.box);
    }
    // A primitive that fills its box (a thin spike) gains nothing from several boxes.
    if (!tested && total >= volume(region))
        cull_.assign(1, {region, 0, 0, 0, static_cast<std::uint32_t>(parts_.size())});
    if (cull_.size() == 1 && !tested) split_in_halves();
}

// One box is cut in two along its longest axis. The accelerator bounds each part in world
// space, and a placed instance is turned at any angle: more than half the visits of a lattice
// box (7 x 7 x 20 cells) came from rays that met its world box and missed the box itself; two
// halves have tighter world boxes, and a ray meeting both still visits once. Instructions on
// the complexity scenes (dense): CSG of 1 torus -18 %, of 4 and 12 tori -5 and -6 %, tufts of
// 200 and 2,000 parts -3 and -5 %.
void LatticeFrame::split_in_halves() {
    const Bounds3 whole = cull_.front().box;
    if (whole.empty()) return;
    const Vec3 ext = whole.extent();
    const std::size_t axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    Bounds3 low = whole, high = whole;
    low.hi[axis] = high.lo[axis] = whole.lo[axis] + 0.5 * ext[axis];
    const std::uint32_t first = cull_.front().part_first, count = cull_.front().part_count;
    cull_ = {{low, 0, 0, first, count, whole}, {high, 0, 0, first, count, whole}};
}

bool LatticeFrame::cull_meets(std::size_t i, const Ray& r, double narrower) const {
    assert(narrower >= 0);  // and at most the reach the frame was made with
    const CullPart& p = cull_[i];
    if (p.count == 0) return true;
    for (std::uint32_t k = p.first; k < p.first + p.count; ++k)
        if (capsules_[k].meets_line(r.o, r.d, capsules_[k].r - narrower)) return true;
    return false;
}

bool LatticeFrame::cull_meets_any(const Ray& r, double narrower) const {
    if (screen_.empty()) {
        for (std::size_t i = 0; i < cull_.size(); ++i)
            if (cull_meets(i, r, narrower)) return true;
        return false;
    }
    // Every part's capsules are among capsules_, and the screen names each one its test
    // (cull_meets') may accept.
    for (std::uint32_t m = screen_.may_meet(r.o, r.d, narrower); m != 0; m &= m - 1) {
        const Capsule& c = capsules_[static_cast<std::size_t>(std::countr_zero(m))];
        if (c.meets_line(r.o, r.d, c.r - narrower)) return true;
    }
    return false;
}

// Any affine map takes the capsule's ball into an ellipsoid within max_stretch times its
// radius, so the placed segment's capsule of that radius holds the placed capsule. It is grown
// by far more than the rounding of the placement (a few ulps of the placed coordinates and of
// the translation, which can cancel) and of either test on the near side; the far side, a
// far origin's rounding, is FloatCapsule's. So it never rejects a line that the test in the
// shape's space accepts (tests/lattice_shape_test.cpp).
bool LatticeFrame::cull_capsule(std::size_t i, const Transform& xf, Capsule& out,
                                double narrower) const {
    assert(narrower >= 0 && narrower <= max_narrower_);
    const CullPart& p = cull_[i];
    if (p.count != 1) return false;
    const Capsule& c = capsules_[p.first];
    out.a = xf.point(c.a), out.b = xf.point(c.b);
    const double scale = max_component(abs(out.a)) + max_component(abs(out.b)) +
                         max_component(abs(xf.point({0, 0, 0})));
    out.r = (c.r - narrower) * xf.max_stretch() * (1 + 1e-9) + 1e-9 * scale;
    return true;
}

// A point within the reach of a part (primitive units) lies within reach times the largest
// stretch of xf of the placed part.
Bounds3 LatticeFrame::placed_parts(const CullPart& p, const Transform& xf, double narrower) const {
    const double grow = (reach_ - narrower) * xf.max_stretch();
    Bounds3 placed;
    for (std::uint32_t k = p.part_first; k < p.part_first + p.part_count; ++k)
        placed = merge(placed, expand(primitive_->part_bounds(parts_[k], xf), grow));
    return placed;
}

// Narrowed, a box around parts grown by the reach (and clipped to the region, the box grown by
// as much: make_lattice_shape, FilteredLatticeShape) shrinks by as much on every side: an
// axis-aligned box shrinks the same whether clipped before or after. A half's cut face was not
// grown: the whole box shrinks, and the half is what of it lies on its side.
Bounds3 LatticeFrame::cull_bounds(std::size_t i, const Transform& xf, double narrower) const {
    assert(narrower >= 0 && narrower <= max_narrower_);
    const CullPart& p = cull_[i];
    const Bounds3 narrowed =
        narrower > 0 ? lat::intersect(expand(p.whole.empty() ? p.box : p.whole, -narrower), p.box)
                     : p.box;
    Bounds3 bounds = xf.bounds(narrowed);
    if (p.part_count > 0) bounds = lat::intersect(bounds, placed_parts(p, xf, narrower));
    if (p.count == 0) return bounds;
    Bounds3 placed;
    for (std::uint32_t k = p.first; k < p.first + p.count; ++k) {
        const Capsule& c = capsules_[k];
        placed = merge(placed, Capsule{c.a, c.b, c.r - narrower}.placed_bounds(xf));
    }
    return lat::intersect(bounds, placed);
}

bool LatticeFrame::snap(const Ray& r, Snap& s) const {
    stats::bump(stats::Counter::kLatticeVisits);
    const Vec3 o = r.o * inv_cell_, d = r.d * inv_cell_;
    s.o = o;
    s.d = d;
    switch (snap_float(o, d, grid_.cells(), s.pa, s.pb)) {
        case FloatSnap::kMiss: return false;
        case FloatSnap::kPair: break;
        case FloatSnap::kUnsure: return snap_double(r, s);
    }
    s.a = grid_.id(s.pa);
    s.b = grid_.id(s.pb);
    return true;
}

bool LatticeFrame::snap_double(const Ray& r, Snap& s) const {
    s.o = r.o * inv_cell_;
    s.d = r.d * inv_cell_;
    if (!snap_points(s)) return false;
    s.a = grid_.id(s.pa);
    s.b = grid_.id(s.pb);
    return true;
}

bool LatticeFrame::visit_chord(const Ray& r, Vec3& o, Vec3& d, Chord& c) const {
    stats::bump(stats::Counter::kLatticeVisits);
    o = r.o * inv_cell_;
    d = r.d * inv_cell_;
    return chord(o, d, c);
}

bool LatticeFrame::chord(const Vec3& o, const Vec3& d, Chord& c) const {
    const auto& n = grid_.cells();
    c = Chord{-kInfinity, kInfinity};
    for (int k = 0; k < 3; ++k) {
        const auto uk = static_cast<std::size_t>(k);
        if (d[uk] == 0) {
            if (o[uk] < 0 || o[uk] > n[uk]) return false;
            continue;
        }
        const double inv = 1.0 / d[uk];
        double tn = -o[uk] * inv, tf = (n[uk] - o[uk]) * inv;
        if (tn > tf) std::swap(tn, tf);
        if (tn > c.t0) c.t0 = tn, c.ax0 = k, c.high0 = d[uk] < 0;
        if (tf < c.t1) c.t1 = tf, c.ax1 = k, c.high1 = d[uk] > 0;
    }
    return c.t0 <= c.t1 && c.ax0 >= 0 && c.ax1 >= 0;
}

// Rounds the entry and exit points to the nearest grid points on their faces, in double. The
// grid points are written field by field: built a coordinate at a time through GridPoint's
// operator[], they went through a stack copy that was read back as one 8-byte load of two
// 4-byte stores, which stalled store forwarding twice a visit.
bool LatticeFrame::snap_points(Snap& s) const {
    Chord c;
    if (!chord(s.o, s.d, c)) return false;
    const auto& n = grid_.cells();
    const auto on_face = [&](double t, int axis, bool high, GridPoint& g) {
        const Vec3 x = s.o + s.d * t;
        const auto coord = [&](int k, double xk) {
            const int nk = n[static_cast<std::size_t>(k)];
            if (k == axis) return high ? nk : 0;
            return static_cast<int>(std::clamp(std::nearbyint(xk), 0.0, double(nk)));
        };
        g.x = coord(0, x.x);
        g.y = coord(1, x.y);
        g.z = coord(2, x.z);
    };
    on_face(c.t0, c.ax0, c.high0, s.pa);
    on_face(c.t1, c.ax1, c.high1, s.pb);
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
