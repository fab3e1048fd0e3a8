#include "lattice/filtered_shape.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "geometry/ray_quad.h"
#include "geometry/sub_rays.h"

namespace lat {
namespace {

// What a ray without a footprint is taken to have: a zero one (the finest level), no
// directions across it, no bound.
constexpr RayFootprint kNoFootprint{};
const RayFootprint& footprint_of(const Ray& r) {
    return r.footprint ? *r.footprint : kNoFootprint;
}

// How far (in cells of a level) a ray answered through a level can pass from the primitive: a
// pair blended in has its ends within sqrt(2) cells of the ray's (smooth: a neighbouring grid
// point in both face directions; box: kSnapReach), and a sub-ray of that pair that meets the
// primitive lies within kSnapReach of the pair's segment.
double reach_cells(LatticeFilter f) {
    return (f == LatticeFilter::kSmooth ? std::sqrt(2.0) : kSnapReach) + kSnapReach;
}

// The smooth filter's culling cuts its tent at this distance (cells of the culling level): the
// bound above is met only by pairs of tiny weight at the far corners of the blend's simplex.
// Coverage lost (Coverage.CullingKeepsNearlyAllTheCoverage: a hair 0.16 coarse cells thick and
// the hook, lines and rays starting inside): at most 3.4e-4 of the coarser level's rays'
// coverage, 1e-6 of the culling level's; at 1.5 cells 4.1e-3 (the thin hair), at the bound
// 2.7e-5. Plates 4 and 5 and the furry bunny render 4 %, 7 % and 10 % faster than at the bound,
// with the same PSNR to 0.01 dB.
constexpr double kSmoothCullCells = 1.8;
double cull_cells(LatticeFilter f) {
    return std::min(reach_cells(f), kSmoothCullCells);
}

// Exact crossings of a chain of at least this many parts test the parts' boxes first.
constexpr std::size_t kMinBoxedParts = 8;

}  // namespace

double lod_level(double cell0, double width) {
    return std::log2(cell0 / (width * kCellPerFootprint));
}

double farthest_sub_ray(double width) {
    // The corner one of n x n: sqrt(2) (n - 1) / 2n of the width from the ray, 1 % more for
    // directions across it that are perpendicular within 1e-3 only (geometry/sub_rays.h).
    constexpr int n = kExactSubRays;
    return width * std::sqrt(2.0) * (n - 1) / (2 * n) * 1.01;
}

bool answered_by_primitive(const Shape& primitive) {
    return dynamic_cast<const ChainShape*>(&primitive) != nullptr ||
           primitive.intersect_cost() <= kMaxExactCost;
}

double lod_blend(double f, double band) {
    if (band <= 0) return f < 0.5 ? 0.0 : 1.0;
    return std::clamp((f - 0.5) / band + 0.5, 0.0, 1.0);
}

FilteredLatticeShape::FilteredLatticeShape(std::vector<FilterLevel> levels, LatticeFilter filter,
                                           double table_error, double exact_width)
    // The point-sampled finest level reaches as far as make_lattice_shape's lattices do.
    : filter_(filter),
      primitive_(levels.back().ctx.primitive),
      exact_(exact_width > 0 && primitive_),
      exact_width_(exact_width),
      sub_ray_reach_(farthest_sub_ray(exact_width)) {
    assert(!levels.empty() && filter != LatticeFilter::kNone);
    assert(std::all_of(levels.begin(), levels.end(),
                       [&](const FilterLevel& l) { return l.ctx.primitive == primitive_; }));
    // scene_lattices leaves the table out only where exact_ holds (the same rule): without it,
    // add_tables would read null.
    for (const FilterLevel& l : levels)
        if (!l.table && !exact_)
            throw std::logic_error(
                "a filtered lattice without a table must answer by its crossings");
    if (levels.back().table)
        point_.emplace(levels.back().table, levels.back().ctx,
                       levels.back().ctx.cell * kSnapReach + table_error);
    // One level's frame culls: the coarsest level's reach would keep every ray its filter
    // reaches, but the next level's, half as far, keeps nearly all of its coverage (the far
    // part of the support carries little weight: see kSmoothCullCells; `box`, which blends the
    // levels all the way, loses at most 1.4e-3 of the coarse level's) and costs far less: with
    // the coarsest level's reach, every ray met its fatter boxes, though most rays read finer
    // levels. Unlike a point-sampled lattice's, this reach is a cut, not a bound (even the
    // bound lets a ray starting inside the box lose a little: a sheet's point is a blend).
    // Both cuts, smooth, 1 spp: Plates 4 and 5 render 18 % and 23 % faster, the furry bunny
    // and grass 37 % and 44 %, with the same PSNR against exact ground truth to 0.06 dB
    // (docs/filtering.md, "Culling").
    // A primitive answered by its own crossings reads no table (point_ serves it as a CSG
    // leaf, and scene_lattices loads none elsewhere): its one level's frame culls, with the
    // parts grown by the farthest sub-ray's distance from the ray (a bound; each instance by
    // its own, cull_bounds, and each ray by its own, cull_meets), and a ray whose line passes
    // that close outside the box can have sub-rays that enter it.
    assert(!exact_ || levels.size() == 1);
    cull_level_ = std::min<std::size_t>(1, levels.size() - 1);
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const FilterLevel& l = levels[i];
        const double reach = i != cull_level_ ? kInfinity
                             : exact_         ? sub_ray_reach_
                                              : cull_cells(filter) * l.ctx.cell + table_error;
        levels_.push_back({l.table, LatticeFrame(l.ctx, reach, exact_ ? sub_ray_reach_ : 0.0),
                           BoundaryGrid(l.ctx.cells)});
    }
    bounds_ = exact_ ? expand(box(), sub_ray_reach_) : box();
    // A chain's crossing is the first of its parts' in order (ChainShape::intersect), so any
    // superset of the parts a sub-ray can meet, in order, gives it bit for bit. Boxes pay for
    // their set-up on a hair of 19 parts, not on a thistle spike of 3 (Plate 2 rendered 9 %
    // slower when every sub-ray tested the boxes).
    chain_ = exact_ ? dynamic_cast<const ChainShape*>(primitive_) : nullptr;
    if (chain_ && chain_->primitive_count() >= kMinBoxedParts)
        part_boxes_ = std::make_unique<const PartBoxes>(*chain_, box(), true);
    paired_shadows_ = exact_ && !chain_ && primitive_->intersect_cost() > kMaxExactCost;
    box_shadows_ = !exact_ && primitive_ && !dynamic_cast<const ChainShape*>(primitive_) &&
                   primitive_->intersect_cost() > kMaxExactCost;
}

void FilteredLatticeShape::spans(const Ray& r, SpanList& out) const {
    if (point_) point_->spans(r, out);
    else primitive_->spans(r, out);
}

bool FilteredLatticeShape::inside(Vec3 p) const {
    return point_ ? point_->inside(p) : primitive_->inside(p);
}

void FilteredLatticeShape::blend(const Level& l, const Ray& r, double weight, bool smooth,
                                 Blend& out) const {
    LatticeFrame::Snap sn;
    if (!l.frame.snap(r, sn)) return;
    if (!smooth) {
        out.add(l.grid, sn.pa, sn.pb, weight);
        return;
    }
    // The real entry and exit points, on the faces snap chose (the axes that clip first and
    // last), in face coordinates u, v (the next two axes).
    const auto& n = l.grid.cells();
    LatticeFrame::Chord ch;
    if (!l.frame.chord(sn.o, sn.d, ch)) return;  // (not reached: snap met the box)
    const int ax[2] = {ch.ax0, ch.ax1};
    const Vec3 x[2] = {sn.o + sn.d * ch.t0, sn.o + sn.d * ch.t1};
    // The 4-D coordinates (u, v of the entry, u, v of the exit): the corners' coordinates
    // start at their cell's (c), each with its fraction in the cell and the axis it moves.
    int c[2][3] = {{sn.pa.x, sn.pa.y, sn.pa.z}, {sn.pb.x, sn.pb.y, sn.pb.z}};
    double frac[4];
    int axis_of[4];
    for (int e = 0; e < 2; ++e)
        for (int j = 0; j < 2; ++j) {
            const int a = kFaceAxes[ax[e]][j];
            const int na = n[static_cast<std::size_t>(a)];
            const double v = std::clamp(x[e][static_cast<std::size_t>(a)], 0.0, double(na));
            // floor: v >= 0.
            const int b = std::min(static_cast<int>(v), std::max(0, na - 1));
            c[e][a] = b;
            frac[2 * e + j] = std::clamp(v - b, 0.0, 1.0);
            axis_of[2 * e + j] = a;
        }
    // The coordinates by decreasing fraction (a sorting network; ties in either order give the
    // same pairs, the step between tied coordinates having weight 0).
    int order[4] = {0, 1, 2, 3};
    auto sort2 = [&](int i, int j) {
        if (frac[order[j]] > frac[order[i]]) std::swap(order[i], order[j]);
    };
    sort2(0, 1), sort2(2, 3), sort2(0, 2), sort2(1, 3), sort2(1, 2);
    // Walk the simplex from the base corner, adding one coordinate at a time (Kuhn).
    double prev = 1;
    for (int step = 0; step <= 4; ++step) {
        const double f = step < 4 ? frac[order[step]] : 0;
        if (prev - f > 0)
            out.add(l.grid, {c[0][0], c[0][1], c[0][2]}, {c[1][0], c[1][1], c[1][2]}, weight * (prev - f));
        prev = f;
        if (step < 4) ++c[order[step] / 2][axis_of[order[step]]];
    }
}

void FilteredLatticeShape::add_blend(const Level& l, const Blend& b, bool normals, const Ray& r,
                                     double tmin, Sheet& s) const {
    CoverageHit h[Blend::kMaxPairs];
    bool found[Blend::kMaxPairs];
    l.table->coverage_at(b.ref, b.n, h, found, normals);
    // A pair answers with its first crossing; a ray that starts inside the box (a shadow ray
    // leaving a surface among the fur) can have that crossing behind it, and the pair then
    // answers with its last crossing, the first one of the reversed pair (as point-sampled
    // lattices do, HitTableShape::line_hits): a hair whose line through the box is crossed
    // behind and ahead of the ray's start still blocks it.
    const double dd = dot(r.d, r.d);
    // Adds pair i of `bl` (looked up as h) if r meets its crossing after tmin.
    auto add_if_ahead = [&](const Blend& bl, int i, const CoverageHit& hi) {
        const Vec3 p = lerp(to_vec(bl.ca[i]), to_vec(bl.cb[i]), hi.t) * l.frame.cell();
        if (dot(p - r.o, r.d) / dd <= tmin) return false;
        s.add(bl.w[i], hi, p);
        return true;
    };
    Blend back;
    for (int i = 0; i < b.n; ++i) {
        if (!found[i] || add_if_ahead(b, i, h[i])) continue;
        back.ia[back.n] = b.ib[i], back.ib[back.n] = b.ia[i];
        back.ca[back.n] = b.cb[i], back.cb[back.n] = b.ca[i], back.w[back.n] = b.w[i];
        ++back.n;
    }
    if (back.n == 0) return;
    l.table->coverage_many(back.ia, back.ib, back.n, h, found, normals);
    for (int i = 0; i < back.n; ++i)
        if (found[i]) add_if_ahead(back, i, h[i]);
}

bool FilteredLatticeShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    return sheet(r, tmin, tmax, !footprint_of(r).coverage_only, hit);
}

bool FilteredLatticeShape::sheet(const Ray& r, double tmin, double tmax, bool normal,
                                 Crossing& hit) const {
    Sheet s;
    double finer = 0;  // how many levels finer than the finest table the footprint is
    if (exact_) {
        SubRayHits h;
        exact_sub_rays(sub_ray_width(r), normal, r, tmin, tmax, h);
        add_sub_rays(h, h.met, s);
    } else {
        // Rays without a footprint read the finest table.
        const double width = footprint_width(r);
        const double top = double(levels_.size() - 1);
        const double wanted = width > 0 ? lod_level(levels_.front().frame.cell(), width) : top;
        const double level = std::clamp(wanted, 0.0, top);
        finer = std::max(0.0, wanted - level);
        add_tables(level, normal, r, tmin, s);
    }
    return to_crossing(s, finer, r, tmin, tmax, normal, hit);
}

int FilteredLatticeShape::sheets(const Ray& r, double tmin, double tmax,
                                 std::span<SheetCrossing, kMaxSheets> out) const {
    const RayFootprint& f = footprint_of(r);
    const bool normal = !f.coverage_only;
    // Sheets of sub-rays are told apart only where they compose sub-ray by sub-ray
    // (LayerComposite): with the world's directions across the ray.
    if (!exact_ || !normal || !f.across) {
        out[0].normals.count = 0;
        return sheet(r, tmin, tmax, normal, out[0].crossing) ? 1 : 0;
    }
    SubRayHits h;
    const double width = sub_ray_width(r);
    exact_sub_rays(width, true, r, tmin, tmax, h);
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
        if (to_crossing(s, 0, r, tmin, tmax, true, c.crossing)) ++n;
    }
    return n;
}

double FilteredLatticeShape::sub_ray_width(const Ray& r) const {
    // The instance's own bound, by which its culling was narrowed (cull_bounds).
    return std::min({footprint_width(r), exact_width_, footprint_of(r).widest});
}

void FilteredLatticeShape::add_sub_rays(const SubRayHits& h, unsigned which, Sheet& s,
                                        SubRayNormals* normals) {
    constexpr double w = 1.0 / kSubRays;
    if (normals) normals->count = 0;
    for (unsigned m = which; m != 0; m &= m - 1) {
        const int k = std::countr_zero(m);
        s.add_opaque(w, h.p[k], h.n[k]);
        s.sub_rays |= static_cast<std::uint8_t>(1u << k);
        if (normals && h.n[k] != Vec3{}) normals->n[normals->count++] = h.n[k];
    }
}

bool FilteredLatticeShape::to_crossing(const Sheet& s, double finer, const Ray& r, double tmin,
                                       double tmax, bool normal, Crossing& hit) const {
    if (s.alpha <= 1e-6) return false;
    const double dd = dot(r.d, r.d);
    const Vec3 p = s.p / s.alpha;
    const double t = dot(p - r.o, r.d) / dd;
    if (!(t > tmin && t < tmax)) return false;
    // Blends of full pairs round to just under 1: they are opaque (and end the ray's traversal).
    const float coverage = s.alpha >= 1 - 1e-6 ? 1.0f : static_cast<float>(s.alpha);
    const Vec3 facing = -r.d / std::sqrt(dd);
    // The sub-rays of a ray whose directions across are the world's compose with the other
    // lattices' (LayerComposite); otherwise the coverage alone, as the tables'.
    const std::uint8_t sub_rays = exact_ && footprint_of(r).across ? s.sub_rays : 0;
    if (!normal) {
        hit = Crossing(t, 0, SurfacePoint{p, facing});
        hit.coverage = coverage;
        hit.sub_rays = sub_rays;
        return true;
    }
    // The normal is the coverage-weighted mean of unit normals, left unnormalised: its length
    // (below 1 where they diverge) tells the shading how much the normals under the footprint
    // spread (SurfaceHit::normal_length). The sub-rays' normals spread over the footprint
    // itself: as they are. The tables' pairs give their spread over the filter's tent, about a
    // cell of the level wide; a footprint narrower than the finest level's cell (close-ups)
    // covers less of it, and for smooth surfaces the spread, 1 - length, goes as the width
    // squared (unscaled, scaled, without normal filtering: Plate 2, thistles, 36.3, 39.6,
    // 39.6 dB; Plate 3, a hair close up, 42.2, 43.1, 43.1 dB; Plates 4 and 5 need no scaling).
    Vec3 n = s.n / s.alpha;
    if (const double ln = length(s.n); !exact_ && ln > 0) {
        const double len = 1 - (1 - std::min(1.0, ln / s.alpha)) * std::exp2(-2 * finer);
        n = s.n / ln * len;
    }
    hit = Crossing(t, 0, SurfacePoint{p, length(n) > 0 ? n : facing});
    hit.coverage = coverage;
    hit.sub_rays = sub_rays;
    return true;
}

double FilteredLatticeShape::footprint_width(const Ray& r) const {
    // At the box's centre along the ray.
    const double dd = dot(r.d, r.d);
    const double tc = dot(bounds().center() - r.o, r.d) / dd;
    const RayFootprint& f = footprint_of(r);
    return (f.width0 + f.spread * std::max(0.0, tc)) * std::sqrt(dd);
}

bool FilteredLatticeShape::cull_meets(std::size_t i, const Ray& r) const {
    // The capsules less the part of the reach this ray's own footprint leaves unused. (The
    // instance's bound is not handed on yet when its cull parts are tested, so a ray wider than
    // it is tested by more reach than it will use: the accelerator's boxes and world capsules
    // were narrowed by the instance's bound already, cull_bounds and cull_capsule.)
    return cull_frame().cull_meets(i, r, unspanned_reach(footprint_width(r)));
}

void FilteredLatticeShape::add_tables(double level, bool normal, const Ray& r, double tmin,
                                      Sheet& s) const {
    const auto lo = static_cast<std::size_t>(std::floor(level));
    // The box filter, constant over a pair's cells, gets its smoothness from blending levels:
    // it blends them all the way (Plate 4: 33.6 dB, in the band only 32.6 dB).
    const bool smooth = filter_ == LatticeFilter::kSmooth && (normal || !box_shadows_);
    const double w_hi = lod_blend(level - double(lo), smooth ? kLodBlendBand : 1.0);
    // The levels of weight above 0: their pairs are found first and located in their tables
    // together, so that the cache misses of the two tables overlap.
    const std::size_t first = w_hi < 1 ? lo : lo + 1, last = w_hi > 0 ? lo + 1 : lo;
    Blend b[2];
    for (std::size_t i = first; i <= last; ++i) {
        Blend& bi = b[i - first];
        blend(levels_[i], r, i == lo ? 1 - w_hi : w_hi, smooth, bi);
        levels_[i].table->locate_coverage(bi.ia, bi.ib, bi.n, bi.ref);
    }
    for (std::size_t i = first; i <= last; ++i) add_blend(levels_[i], b[i - first], normal, r, tmin, s);
}

// The crossings of kExactSubRays^2 sub-rays parallel to r, on a grid across its footprint (for
// camera rays the pixel's box filter, as exact mode at that many samples would, but on this
// primitive only and shaded once a sheet: sheets). A camera ray's are those of the sub-rays' chords
// through the box, however far r may go (tmax): what the tables answer does not depend on the order
// in which the accelerator meets objects either, and the sheet is cut at tmax after. A shadow ray
// wants only the share of its sub-rays blocked before tmax (the light), not where: any part's
// crossing ends a sub-ray's tests, and the sheet lies halfway along the blocked ones' chords.
// The footprint's width is taken across the ray as along it (instances scaled uniformly, as
// instance_footprints assumes).
void FilteredLatticeShape::exact_sub_rays(double width, bool normal, const Ray& r, double tmin,
                                          double tmax, SubRayHits& h) const {
    constexpr int n = kExactSubRays;
    // A union's sub-rays meet only parts near r: found once, with boxes grown by the farthest
    // sub-ray's distance from r, at least its offset along any axis. Plates 4 and 5 render 6 %
    // faster than with every part intersected by every sub-ray; images identical. (Boxes grown
    // by (n - 1) / n of the width, as first written, kept more parts: 2 % slower.)
    thread_local std::vector<std::uint32_t> near;  // grown, never shrunk: no zeroing a ray
    std::span<const std::uint32_t> parts;
    if (part_boxes_) {
        const std::size_t all = chain_->primitive_count();
        if (near.size() < all) near.resize(all);
        const std::span<std::uint32_t> out(near.data(), all);
        parts = {near.data(), part_boxes_->near_parts(r, farthest_sub_ray(width), tmin, out)};
        // Near no part, no sub-ray meets the primitive: found first, before the sub-rays are
        // made. Of the visits of shadow rays, grass and ball-tuft216 find no part near in 44 %
        // and 59 %, the furry bunny and Plate 4 in 27 % and 16 % (their instances' culling
        // capsules are coarser than the parts' boxes).
        if (parts.empty()) {
            h.met = 0;
            return;
        }
    } else if (chain_)
        parts = chain_->all_parts();
    // Along the world's directions across the ray where the renderer set them, so that the
    // k-th sub-ray is the same in every lattice (geometry/sub_rays.h).
    // (Perpendicular to the ray and each other within 1e-3, which farthest_sub_ray allows for:
    // made exactly so, the basis cost Plate 2 a sixth of its time.)
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
unsigned FilteredLatticeShape::sub_ray_crossings(std::span<const std::uint32_t> parts, RayQuad& q,
                                                 unsigned live, QuadCrossings& hits) const {
    if (chain_) return chain_->first_crossings(parts, q, live, hits);
    unsigned found = 0;
    for (int k = 0; k < kSubRays; ++k)
        if (live >> k & 1 && primitive_->intersect(q.ray(k), q.tmin[k], q.tmax[k], hits.c[k]))
            found |= 1u << k;
    return found;
}

unsigned FilteredLatticeShape::blocked_sub_rays(std::span<const std::uint32_t> parts,
                                                const RayQuad& q, unsigned live) const {
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
// (LayerComposite). The shadows of a costly primitive's sub-rays took two thirds of `ball-csg7`'s
// render (6 tori and a sphere, cost 73): with pairs it took 0.79 of exact 4 spp's time for
// 39.44 dB against 38.73, with all four 1.20 for 41.52 dB (2 threads; docs/filtering.md, "Costly
// primitives").
unsigned FilteredLatticeShape::blocked_pairs(const RayQuad& q, unsigned live) const {
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

bool FilteredLatticeShape::occluded(const Ray& r, double tmin, double tmax) const {
    Crossing c;
    return sheet(r, tmin, tmax, false, c) && c.coverage >= 0.5f;
}

}  // namespace lat
