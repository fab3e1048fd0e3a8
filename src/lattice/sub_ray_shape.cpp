#include "lattice/sub_ray_shape.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>

#include "coverage/footprint.h"
#include "geometry/ray_quad.h"
#include "lattice/answer_plan.h"

namespace lat {
namespace {

// Exact crossings of a chain of at least this many parts test the parts' boxes first.
constexpr std::size_t kMinBoxedParts = 8;

}  // namespace

double farthest_sub_ray(double width) {
    // The corner one of n x n: sqrt(2) (n - 1) / 2n of the width from the ray, 1 % more for
    // directions across it that are perpendicular within 1e-3 only (coverage/sub_rays.h).
    constexpr int n = kExactSubRays;
    return width * std::sqrt(2.0) * (n - 1) / (2 * n) * 1.01;
}

// The frame culls with its parts grown by the farthest sub-ray's distance from the ray (a
// bound; each instance by its own, cull_bounds, and each ray by its own, cull_meets), and a ray
// whose line passes that close outside the box can have sub-rays that enter it.
SubRayShape::SubRayShape(const TableContext& ctx, std::shared_ptr<const LatticeTable> table,
                         double table_error, double width)
    : primitive_(ctx.primitive),
      frame_(ctx, farthest_sub_ray(width), farthest_sub_ray(width)),
      width_(width),
      sub_ray_reach_(farthest_sub_ray(width)) {
    assert(primitive_ && width > 0);
    // The point-sampled table reaches as far as make_lattice_shape's lattices do.
    if (table) point_.emplace(std::move(table), ctx, ctx.cell * kSnapReach + table_error);
    bounds_ = expand(box(), sub_ray_reach_);
    // A chain's crossing is the first of its parts' in order (ChainShape::intersect), so any
    // superset of the parts a sub-ray can meet, in order, gives it bit for bit. Boxes pay for
    // their set-up on a long chain, not on a short one (kMinBoxedParts).
    chain_ = as_chain(*primitive_);
    if (chain_ && chain_->part_count() >= kMinBoxedParts)
        part_boxes_ = std::make_unique<const PartBoxes>(ShapeParts(*chain_), box(), true);
    paired_shadows_ = !chain_ && ShapeSource(*primitive_).intersect_cost() > kMaxExactCost;
}

void SubRayShape::spans(const Ray& r, SpanList& out) const {
    if (point_) point_->spans(r, out);
    else primitive_->spans(r, out);
}

bool SubRayShape::inside(Vec3 p) const {
    return point_ ? point_->inside(p) : primitive_->inside(p);
}

bool SubRayShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    return sheet(r, tmin, tmax, !footprint_of(r).coverage_only, hit);
}

bool SubRayShape::occluded(const Ray& r, double tmin, double tmax) const {
    Crossing c;
    return sheet(r, tmin, tmax, false, c) && c.coverage >= 0.5f;
}

bool SubRayShape::sheet(const Ray& r, double tmin, double tmax, bool normal, Crossing& hit) const {
    Sheet s;
    SubRayHits h;
    sub_ray_hits(sub_ray_width(r), normal, r, tmin, tmax, h);
    // A shadow ray's sub-rays count only crossings the camera did not see at all
    // (unseen_share 1): a sub-ray counts whole or not at all, and spread across a shadow
    // footprint wider than the camera's, its lines reach more of what the camera saw. (Cut at
    // the share's middle instead, a million hairs' shadows stayed too dark:
    // bench/notes/scale-log.md.)
    const RayFootprint& f = footprint_of(r);
    unsigned met = h.met;
    if (f.seen_until > 0)
        for (unsigned m = met; m != 0; m &= m - 1)
            if (const int k = std::countr_zero(m); unseen_share(f, h.t[k]) < 1) met &= ~(1u << k);
    add_sub_rays(h, met, s);
    return to_crossing(s, r, tmin, tmax, normal, hit);
}

int SubRayShape::sheets(const Ray& r, double tmin, double tmax,
                        std::span<SheetCrossing, kMaxSheets> out) const {
    const RayFootprint& f = footprint_of(r);
    const bool normal = !f.coverage_only;
    // Sheets of sub-rays are told apart only where they compose sub-ray by sub-ray
    // (LayerComposite): with the world's directions across the ray.
    if (!normal || !f.across) {
        out[0].normals.count = 0;
        return sheet(r, tmin, tmax, normal, out[0].crossing) ? 1 : 0;
    }
    SubRayHits h;
    const double width = sub_ray_width(r);
    sub_ray_hits(width, true, r, tmin, tmax, h);
    const double depth = kSheetDepth * width / std::sqrt(dot(r.d, r.d));  // in r's parameter
    int n = 0;
    // Front to back: the sub-rays within `depth` of the nearest one left make the next sheet.
    for (unsigned left = h.met; left != 0;) {
        double nearest = kInfinity;
        for (unsigned m = left; m != 0; m &= m - 1)
            nearest = std::min(nearest, h.t[std::countr_zero(m)]);
        unsigned group = 0;
        for (unsigned m = left; m != 0; m &= m - 1)
            if (const int k = std::countr_zero(m); h.t[k] <= nearest + depth) group |= 1u << k;
        left &= ~group;
        Sheet s;
        SheetCrossing& c = out[static_cast<std::size_t>(n)];
        add_sub_rays(h, group, s, &c.normals);
        if (to_crossing(s, r, tmin, tmax, true, c.crossing)) ++n;
    }
    return n;
}

double SubRayShape::sub_ray_width(const Ray& r) const {
    // The instance's own bound, by which its culling was narrowed (cull_bounds).
    return std::min({footprint_width(r), width_, footprint_of(r).widest});
}

void SubRayShape::add_sub_rays(const SubRayHits& h, unsigned which, Sheet& s,
                               SubRayNormals* normals) {
    constexpr double w = 1.0 / kSubRays;
    if (normals) normals->count = 0;
    for (unsigned m = which; m != 0; m &= m - 1) {
        const int k = std::countr_zero(m);
        s.add(w, h.p[k], h.n[k]);
        s.sub_rays |= static_cast<std::uint8_t>(1u << k);
        if (normals && h.n[k] != Vec3{}) normals->n[normals->count++] = h.n[k];
    }
}

bool SubRayShape::to_crossing(const Sheet& s, const Ray& r, double tmin, double tmax,
                              bool normal, Crossing& hit) {
    // All four sub-rays: opaque (and the end of the ray's traversal).
    SheetOnRay on;
    if (!sheet_on_ray(s.p, s.alpha, r, tmin, tmax, on)) return false;
    const auto [t, p, coverage, facing] = on;
    // The sub-rays of a ray whose directions across are the world's compose with the other
    // lattices' (LayerComposite); otherwise the coverage alone, as the tables'.
    const std::uint8_t sub_rays = footprint_of(r).across ? s.sub_rays : 0;
    if (!normal) {
        hit = Crossing(t, 0, SurfacePoint{p, facing});
        hit.coverage = coverage;
        hit.sub_rays = sub_rays;
        return true;
    }
    // The mean of the sub-rays' unit normals, left unnormalised: its length (below 1 where
    // they diverge) tells the shading how much the normals under the footprint spread
    // (SurfaceHit::normal_length).
    const Vec3 n = s.n / s.alpha;
    hit = Crossing(t, 0, SurfacePoint{p, length(n) > 0 ? n : facing});
    hit.coverage = coverage;
    hit.sub_rays = sub_rays;
    return true;
}

double SubRayShape::footprint_width(const Ray& r) const {
    return footprint_width_at(r, bounds().center());
}

bool SubRayShape::cull_meets(std::size_t i, const Ray& r) const {
    // The capsules less the part of the reach this ray's own footprint leaves unused. (The
    // instance's bound is not handed on yet when its cull parts are tested, so a ray wider than
    // it is tested by more reach than it will use: the accelerator's boxes and world capsules
    // were narrowed by the instance's bound already, cull_bounds and cull_capsule.)
    return frame_.cull_meets(i, r, unspanned_reach(footprint_width(r)));
}

bool SubRayShape::cull_meets_any(const Ray& r) const {
    return frame_.cull_meets_any(r, unspanned_reach(footprint_width(r)));
}

// The crossings of kExactSubRays^2 sub-rays parallel to r, on a grid across its footprint (for
// camera rays the pixel's box filter, as exact mode at that many samples would, but on this
// primitive only and shaded once a sheet: sheets). A camera ray's are those of the sub-rays'
// chords through the box, however far r may go (tmax), so that the answer does not depend on
// the order in which the accelerator meets objects; the sheet is cut at tmax after. A shadow ray
// wants only the share of its sub-rays blocked before tmax (the light), not where: any part's
// crossing ends a sub-ray's tests, and the sheet lies halfway along the blocked ones' chords.
// The footprint's width is taken across the ray as along it (instances scaled uniformly, as
// instance_footprints assumes).
void SubRayShape::sub_ray_hits(double width, bool normal, const Ray& r, double tmin, double tmax,
                               SubRayHits& h) const {
    constexpr int n = kExactSubRays;
    // A chain's sub-rays meet only parts near r: found once, with boxes grown by the farthest
    // sub-ray's distance from r (at least its offset along any axis), so every part a sub-ray
    // can meet is kept and the answers are those of all the parts.
    // Per-thread scratch, grown, never shrunk: no allocating or zeroing a ray.
    thread_local std::vector<std::uint32_t> near;
    std::span<const std::uint32_t> parts;
    if (part_boxes_) {
        const std::size_t all = chain_->part_count();
        if (near.size() < all) near.resize(all);
        const std::span<std::uint32_t> out(near.data(), all);
        parts = {near.data(), part_boxes_->near_parts(r, farthest_sub_ray(width), tmin, out)};
        // Near no part, no sub-ray meets the primitive: found first, before the sub-rays are
        // made (common: an instance's culling capsules are coarser than its parts' boxes).
        if (parts.empty()) {
            h.met = 0;
            return;
        }
    } else if (chain_)
        parts = chain_->all_parts();
    // Along the world's directions across the ray where the renderer set them, so that the
    // k-th sub-ray is the same in every lattice (coverage/sub_rays.h).
    // (Perpendicular to the ray and each other within 1e-3 only, which farthest_sub_ray allows
    // for: making them exactly so, per ray, costs far more than it could change.)
    const RayFootprint& f = footprint_of(r);
    Vec3 u, v;
    if (f.across) {
        u = normalize(f.u), v = normalize(f.v);
    } else {
        orthonormal_basis(r.d / length(r.d), u, v);
    }
    // The sub-rays, lane k = i n + j (bit k of Sheet::sub_rays), each clipped to the box.
    static_assert(n * n == 4, "a RayQuad holds a ray's sub-rays");
    RayQuad q;
    q.d = r.d;
    const Vec3 inv = reciprocals(r.d);  // the sub-rays' clip_ray, in four
    unsigned live = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const int k = i * n + j;
            const double a = ((i + 0.5) / n - 0.5) * width, b = ((j + 0.5) / n - 0.5) * width;
            const Vec3 o = r.o + u * a + v * b;
            q.ox[k] = o.x, q.oy[k] = o.y, q.oz[k] = o.z;
            double t0 = tmin, t1 = kInfinity;  // clip_line only narrows [t0, t1]
            // A lane clipped away gets a range of 0: its tests run, masked off.
            if (!clip_line(box(), o, r.d, inv, t0, t1)) t0 = t1 = 0;
            q.tmin[k] = t0, q.tmax[k] = normal ? t1 : std::min(t1, tmax);
            if (q.tmin[k] < q.tmax[k]) live |= 1u << k;
        }
    if (!normal) {
        h.met = blocked_sub_rays(parts, q, live);
        for (unsigned m = h.met; m != 0; m &= m - 1) {
            const int k = std::countr_zero(m);
            h.t[k] = 0.5 * (q.tmin[k] + q.tmax[k]);
            h.p[k] = q.ray(k).at(h.t[k]), h.n[k] = {};
        }
        return;
    }
    QuadCrossings hits;
    h.met = sub_ray_crossings(parts, q, live, hits);
    for (unsigned m = h.met; m != 0; m &= m - 1) {
        const int k = std::countr_zero(m);
        const SurfacePoint sp = primitive_->surface(q.ray(k), hits.c[k]);
        const double ln = length(sp.n);
        h.t[k] = hits.c[k].t, h.p[k] = sp.p, h.n[k] = ln > 0 ? sp.n / ln : Vec3{};
    }
}

// A chain's parts take the sub-rays four at once; other primitives one sub-ray at a time.
unsigned SubRayShape::sub_ray_crossings(std::span<const std::uint32_t> parts, RayQuad& q,
                                        unsigned live, QuadCrossings& hits) const {
    if (chain_) return chain_->first_crossings(parts, q, live, hits);
    unsigned found = 0;
    for (int k = 0; k < kSubRays; ++k)
        if (live >> k & 1 && primitive_->intersect(q.ray(k), q.tmin[k], q.tmax[k], hits.c[k]))
            found |= 1u << k;
    return found;
}

unsigned SubRayShape::blocked_sub_rays(std::span<const std::uint32_t> parts, const RayQuad& q,
                                       unsigned live) const {
    if (chain_) return chain_->blocked_lanes(parts, q, live);
    if (paired_shadows_) return blocked_pairs(q, live);
    unsigned blocked = 0;
    for (int k = 0; k < kSubRays; ++k)
        if (live >> k & 1 && primitive_->occluded(q.ray(k), q.tmin[k], q.tmax[k]))
            blocked |= 1u << k;
    return blocked;
}

// The lanes of a shadow ray's 2 x 2 sub-rays (k = i 2 + j) in two pairs, the rows {0, 1} and
// {3, 2}: one test a pair, of its first live lane (0 and 3, on a diagonal), answers for both.
// Every lattice pairs the lanes alike, so a pair blocked in one stays blocked in the next
// (LayerComposite). Why: the shadow rays of a costly primitive's sub-rays dominate its render,
// and pairs halve their tests for little loss (docs/filtering.md, "Costly primitives").
unsigned SubRayShape::blocked_pairs(const RayQuad& q, unsigned live) const {
    static constexpr std::array<std::array<int, 2>, 2> kPairs{{{0, 1}, {3, 2}}};
    unsigned blocked = 0;
    for (const auto& pair : kPairs) {
        const unsigned lanes = (1u << pair[0] | 1u << pair[1]) & live;
        if (lanes == 0) continue;
        const int k = lanes >> pair[0] & 1 ? pair[0] : pair[1];
        if (primitive_->occluded(q.ray(k), q.tmin[k], q.tmax[k])) blocked |= lanes;
    }
    return blocked;
}

}  // namespace lat
