#include "lattice/filtered_shape.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "coverage/footprint.h"

namespace lat {
namespace {

// How far (in cells of a level) a ray answered through a level can pass from the primitive: a
// pair blended in has its ends within sqrt(2) cells of the ray's (smooth: a neighbouring grid
// point in both face directions; box: kSnapReach), and a sub-ray of that pair that meets the
// primitive lies within kSnapReach of the pair's segment.
double reach_cells(LatticeFilter f) {
    return (f == LatticeFilter::kSmooth ? std::sqrt(2.0) : kSnapReach) + kSnapReach;
}

// The smooth filter's culling cuts its tent at this distance (cells of the culling level): the
// bound above is met only by pairs of tiny weight at the far corners of the blend's simplex, so
// the cut loses a negligible share of coverage (Coverage.CullingKeepsNearlyAllTheCoverage
// bounds it) and saves the tests of the rays that meet only that far corner
// (bench/notes/filtering-constants.md has both).
constexpr double kSmoothCullCells = 1.8;
double cull_cells(LatticeFilter f) {
    return std::min(reach_cells(f), kSmoothCullCells);
}

}  // namespace

double lod_level(double cell0, double width) {
    return std::log2(cell0 / (width * kCellPerFootprint));
}

double crossing_share_ahead(double dt, double spread) {
    return std::clamp(dt / spread + 0.5, 0.0, 1.0);
}

double lod_blend(double f, double band) {
    if (band <= 0) return f < 0.5 ? 0.0 : 1.0;
    return std::clamp((f - 0.5) / band + 0.5, 0.0, 1.0);
}

FilteredLatticeShape::FilteredLatticeShape(std::vector<FilterLevel> levels, LatticeFilter filter,
                                           double table_error, bool box_shadows)
    : filter_(filter), box_shadows_(box_shadows) {
    assert(!levels.empty() && filter != LatticeFilter::kNone);
    for (const FilterLevel& l : levels)
        if (!l.table) throw std::logic_error("a filtered lattice needs a table at every level");
    // The point-sampled finest level reaches as far as make_lattice_shape's lattices do.
    point_.emplace(levels.back().table, levels.back().ctx,
                   levels.back().ctx.cell * kSnapReach + table_error);
    // One level's frame culls: the coarsest level's reach would keep every ray its filter
    // reaches, but the next level's, half as far, keeps nearly all of its coverage (the far
    // part of the support carries little weight: see kSmoothCullCells; `box`, which blends the
    // levels all the way, loses a little more) and costs far less: with the coarsest level's
    // reach, every ray meets its fatter boxes, though most rays read finer levels. Unlike a
    // point-sampled lattice's, this reach is a cut, not a bound (even the bound lets a ray
    // starting inside the box lose a little: a sheet's point is a blend). docs/filtering.md,
    // "Culling", has what the cuts cost and save.
    cull_level_ = std::min<std::size_t>(1, levels.size() - 1);
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const FilterLevel& l = levels[i];
        const double reach =
            i != cull_level_ ? kInfinity : cull_cells(filter) * l.ctx.cell + table_error;
        levels_.push_back({l.table, LatticeFrame(l.ctx, reach, 0.0), BoundaryGrid(l.ctx.cells)});
    }
    bounds_ = box();
}

void FilteredLatticeShape::spans(const Ray& r, SpanList& out) const { point_->spans(r, out); }

bool FilteredLatticeShape::inside(Vec3 p) const { return point_->inside(p); }

void FilteredLatticeShape::blend(const Level& l, const Ray& r, double weight, bool smooth,
                                 Blend& out) const {
    if (!smooth) {
        LatticeFrame::Snap sn;
        if (l.frame.snap(r, sn)) out.add(l.grid, sn.pa, sn.pb, weight);
        return;
    }
    // The real entry and exit points, on the faces the chord enters and leaves by (snap's), in
    // face coordinates u, v (the next two axes); the chord alone, in double, not snap's float
    // pass first: the pair it snaps to is not wanted.
    const auto& n = l.grid.cells();
    Vec3 o, d;
    LatticeFrame::Chord ch;
    if (!l.frame.visit_chord(r, o, d, ch)) return;
    const int ax[2] = {ch.ax0, ch.ax1};
    const bool high[2] = {ch.high0, ch.high1};
    const Vec3 x[2] = {o + d * ch.t0, o + d * ch.t1};
    // The 4-D coordinates (u, v of the entry, u, v of the exit): the corners' coordinates
    // start at their cell's (c), each with its fraction in the cell and the axis it moves; the
    // face's own coordinate is its level.
    int c[2][3];
    double frac[4];
    int axis_of[4];
    for (int e = 0; e < 2; ++e) {
        c[e][ax[e]] = high[e] ? n[static_cast<std::size_t>(ax[e])] : 0;
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
    }
    // The coordinates by decreasing fraction (a sorting network; ties in either order give the
    // same pairs, the step between tied coordinates having weight 0).
    int order[4] = {0, 1, 2, 3};
    auto sort2 = [&](int i, int j) {
        if (frac[order[j]] > frac[order[i]]) std::swap(order[i], order[j]);
    };
    sort2(0, 1), sort2(2, 3), sort2(0, 2), sort2(1, 3), sort2(1, 2);
    // Walk the simplex from the base corner, adding one coordinate at a time (Kuhn): each step
    // moves one end, whose id alone is found anew.
    GridPoint p[2] = {{c[0][0], c[0][1], c[0][2]}, {c[1][0], c[1][1], c[1][2]}};
    std::uint32_t id[2] = {l.grid.id(p[0]), l.grid.id(p[1])};
    double prev = 1;
    for (int step = 0; step <= 4; ++step) {
        const double f = step < 4 ? frac[order[step]] : 0;
        if (prev - f > 0) out.add(id[0], id[1], p[0], p[1], weight * (prev - f));
        prev = f;
        if (step == 4) break;
        const int e = order[step] / 2;
        ++p[e][axis_of[order[step]]];
        id[e] = l.grid.id(p[e]);
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
    // behind and ahead of the ray's start still blocks it. A crossing near the start counts
    // for its share ahead of it (crossing_share_ahead).
    const double dd = dot(r.d, r.d);
    const double spread = kCrossingSpreadCells * l.frame.cell() / std::sqrt(dd);  // in t
    const RayFootprint& f = footprint_of(r);
    // Adds pair i of `bl` (looked up as h) for the share of its crossings r meets after tmin,
    // and of that, a shadow ray's share unseen by the camera (unseen_share); false when the
    // share ahead is 0.
    auto add_if_ahead = [&](const Blend& bl, int i, const CoverageHit& hi) {
        const Vec3 p = lerp(to_vec(bl.ca[i]), to_vec(bl.cb[i]), hi.t) * l.frame.cell();
        const double t = dot(p - r.o, r.d) / dd;
        const double ahead = crossing_share_ahead(t - tmin, spread);
        if (ahead <= 0) return false;
        s.add(bl.w[i] * ahead * unseen_share(f, t), hi, p);
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

FilteredLatticeShape::Lod FilteredLatticeShape::lod_of(const Ray& r) const {
    // Rays without a footprint read the finest table.
    const double width = footprint_width(r);
    const double top = double(levels_.size() - 1);
    const double wanted = width > 0 ? lod_level(levels_.front().frame.cell(), width) : top;
    const double level = std::clamp(wanted, 0.0, top);
    return {width, level, std::max(0.0, wanted - level)};
}

bool FilteredLatticeShape::sheet(const Ray& r, double tmin, double tmax, bool normal,
                                 Crossing& hit) const {
    Sheet s;
    const Lod lod = lod_of(r);
    add_tables(lod.level, normal, r, tmin, s);
    return to_crossing(s, lod.finer, r, tmin, tmax, normal, hit);
}

int FilteredLatticeShape::sheets(const Ray& r, double tmin, double tmax,
                                 std::span<SheetCrossing, kMaxSheets> out) const {
    out[0].normals.count = 0;
    if (footprint_of(r).coverage_only) return sheet(r, tmin, tmax, false, out[0].crossing) ? 1 : 0;
    Sheet s;
    s.keep_pairs = true;
    const Lod lod = lod_of(r);
    add_tables(lod.level, true, r, tmin, s);
    return split(s, lod, r, tmin, tmax, out);
}

int FilteredLatticeShape::depth_clusters(const Sheet& s, const Ray& r, double depth,
                                         Cluster* out) {
    const double dd = dot(r.d, r.d);
    // The pairs in ray order (an insertion sort: at most kMaxPairParts).
    double t[kMaxPairParts];
    int order[kMaxPairParts];
    for (int i = 0; i < s.pairs; ++i) {
        const PairPart& q = s.part[i];
        t[i] = dot(Vec3{q.p[0], q.p[1], q.p[2]} - r.o, r.d) / dd;
        order[i] = i;
        for (int j = i; j > 0 && t[order[j]] < t[order[j - 1]]; --j) std::swap(order[j], order[j - 1]);
    }
    int m = 0;
    for (int i = 0; i < s.pairs; ++m) {
        Cluster& c = out[m];
        c = Cluster{};
        for (const double t0 = t[order[i]]; i < s.pairs && t[order[i]] <= t0 + depth; ++i) {
            const PairPart& q = s.part[order[i]];
            c.alpha += q.a;
            c.p += Vec3{q.p[0], q.p[1], q.p[2]} * q.a;
            c.n += Vec3{q.n[0], q.n[1], q.n[2]} * q.a;
        }
    }
    return m;
}

int FilteredLatticeShape::split(const Sheet& s, const Lod& lod, const Ray& r, double tmin,
                                double tmax, std::span<SheetCrossing, kMaxSheets> out) const {
    const double depth = kSheetDepthFootprints *
                         std::max(lod.width, levels_.back().frame.cell()) / length(r.d);
    Cluster c[kMaxPairParts];
    const int m = depth_clusters(s, r, depth, c);
    int n = 0;
    double drawn = 0, left = s.alpha;  // coverage in sheets so far; in clusters not yet in one
    for (int i = 0; i < m;) {
        // A sheet: clusters until it covers kMinSheetShare and so does the rest (the last
        // takes all that is left), placed at its largest cluster (see kSheetDepthFootprints).
        Cluster g;
        int largest = i;
        for (; i < m; ++i) {
            if (g.alpha >= kMinSheetShare && left - g.alpha >= kMinSheetShare && n < kMaxSheets - 1)
                break;
            g.alpha += c[i].alpha, g.p += c[i].p, g.n += c[i].n;
            if (c[i].alpha > c[largest].alpha) largest = i;
        }
        left -= g.alpha;
        Sheet sheet;
        sheet.alpha = g.alpha, sheet.n = g.n;
        sheet.p = c[largest].p * (g.alpha / c[largest].alpha);
        SheetCrossing& sc = out[static_cast<std::size_t>(n)];
        sc.normals.count = 0;
        if (!to_crossing(sheet, lod.finer, r, tmin, tmax, true, sc.crossing)) continue;
        // Composited behind the sheets before it, a sheet covers its own share of the footprint.
        const double uncovered = 1 - drawn;
        const double alpha = uncovered > 1e-6 ? std::min(1.0, g.alpha / uncovered) : 1.0;
        sc.crossing.coverage = alpha >= 1 - 1e-6 ? 1.0f : static_cast<float>(alpha);
        drawn += g.alpha;
        ++n;
        if (sc.crossing.coverage >= 1.0f) break;  // opaque: nothing behind it is seen
    }
    return n;
}

bool FilteredLatticeShape::to_crossing(const Sheet& s, double finer, const Ray& r, double tmin,
                                       double tmax, bool normal, Crossing& hit) const {
    // Blends of full pairs round to just under 1: they are opaque (and end the ray's traversal).
    SheetOnRay on;
    if (!sheet_on_ray(s.p, s.alpha, r, tmin, tmax, on)) return false;
    const auto [t, p, coverage, facing] = on;
    if (!normal) {
        hit = Crossing(t, 0, SurfacePoint{p, facing});
        hit.coverage = coverage;
        return true;
    }
    // The normal is the coverage-weighted mean of unit normals, left unnormalised: its length
    // (below 1 where they diverge) tells the shading how much the normals under the footprint
    // spread (SurfaceHit::normal_length). The tables' pairs give their spread over the
    // filter's tent, about a cell of the level wide; a footprint narrower than the finest
    // level's cell (close-ups) covers less of it, and for smooth surfaces the spread,
    // 1 - length, goes as the width squared: scaled so, close-ups shade as without normal
    // filtering (bench/notes/filtering-constants.md).
    Vec3 n = s.n / s.alpha;
    if (const double ln = length(s.n); ln > 0) {
        const double len = 1 - (1 - std::min(1.0, ln / s.alpha)) * std::exp2(-2 * finer);
        n = s.n / ln * len;
    }
    hit = Crossing(t, 0, SurfacePoint{p, length(n) > 0 ? n : facing});
    hit.coverage = coverage;
    return true;
}

double FilteredLatticeShape::footprint_width(const Ray& r) const {
    return footprint_width_at(r, bounds().center());
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

bool FilteredLatticeShape::occluded(const Ray& r, double tmin, double tmax) const {
    Crossing c;
    return sheet(r, tmin, tmax, false, c) && c.coverage >= 0.5f;
}

}  // namespace lat
