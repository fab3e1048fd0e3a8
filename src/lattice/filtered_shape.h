#pragma once
// A lattice rendered through its prefiltered tables (tables with Encoding::coverage); a
// primitive answered by its own crossings of sub-rays is lattice/sub_ray_shape.h's, and which
// of them serves a primitive lattice/answer_plan.h decides.
// A ray gets one "sheet" from the lattice: a point, a normal and a coverage alpha, the share of
// the rays around it that meet the primitive. The renderer shades alpha of it and lets the ray
// go on behind for the rest (coverage/layers.h). Filters:
//   box     the coverage of the pair the ray snaps to (constant over the pair's cells);
//   smooth  the coverages of the 5 pairs around the ray's real entry and exit points, blended
//           linearly over a simplex of the 4-D (entry, exit) grid: continuous in ray space.
// Levels of detail: tables of the same box at sigma^-1 doubling from level to level; each ray
// takes the level whose cell matches its footprint (Ray::footprint), blending the two nearest.
// As a CSG leaf, for `inside` and for spans, the lattice is point-sampled through the finest
// level's own hits, exactly as without filtering.
#include <algorithm>
#include <array>
#include <cassert>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "coverage/sheets.h"
#include "geometry/parts.h"
#include "lattice/boundary_grid.h"
#include "lattice/hit_table_shape.h"

namespace lat {

enum class LatticeFilter { kNone, kBox, kSmooth };
// The option names, "none", "box" and "smooth": the one place they are spelled.
inline constexpr std::array<std::pair<std::string_view, LatticeFilter>, 3> kLatticeFilterNames{
    {{"none", LatticeFilter::kNone}, {"box", LatticeFilter::kBox}, {"smooth", LatticeFilter::kSmooth}}};

// A level's cell is made this many footprints wide: the box over a cell, widened by the smooth
// filter's linear blend, then matches a pixel's box best (tuned on six fur scenes against the
// 256-spp exact image; bench/notes/filtering-constants.md).
inline constexpr double kCellPerFootprint = 0.78;
// The level (real; 0 is the lattice of cell cell0, each next one halves it) for a footprint of
// this width, in the same units.
double lod_level(double cell0, double width);
// Levels are blended only within a band of this width around the midpoint between two (as
// "brilinear" texture filtering does): elsewhere a ray reads one level, half the lookups of a
// blend, for a loss under 0.2 dB; a band, not the nearest level alone, keeps changes of level
// across an image from showing as seams (bench/notes/filtering-constants.md).
inline constexpr double kLodBlendBand = 0.25;
// The weight of the finer of two levels at fraction f (0 to 1) of the way to it.
double lod_blend(double f, double band);
// A pair's coverage stands for sub-rays across a cell on either side of its segment (the
// smooth filter's tent), whose crossings spread along a ray as well as across it: a ray that
// starts among them (a shadow ray leaving a surface among fur, inside other hairs' boxes)
// meets the share of them ahead of its start, taken as spread evenly over this many cells of
// the level along the ray, centred on their mean. Counting all or none of them as the mean lay
// ahead or behind made a shadow a step function of where the ray starts: a million hairs on
// the bunny (1280 x 720, against 64-spp exact) 31.46 dB, with the share 33.45 dB; on the
// modes benchmark's scenes within 0.13 dB either way (bench/notes/filtering-constants.md).
inline constexpr double kCrossingSpreadCells = 2;
// A camera ray's pairs whose crossings lie within this many footprints (or finest cells, if
// wider) in depth of the nearest pair of a cluster are of one surface. A sheet blending two
// clusters is shaded at its largest cluster's point: their mean put a tube seen beside another
// behind it at a point between the two, inside the object, in shadow from both lights (the
// burr's dark speckle). 1 and 4 do about as well on the burrs (bench/notes/scale-log.md).
inline constexpr double kSheetDepthFootprints = 2;
// Clusters apart in depth make sheets of their own, each shaded with its own shadow rays, when
// each side covers at least this share of the footprint; less would cost more shadow rays than
// it brings (burrs: 0.25 costs 8 % more table visits for +0.65 dB, 0.1 +21 % render time).
inline constexpr double kMinSheetShare = 0.25;
// The share of crossings spread over `spread` (in t, centred on their mean) that lie ahead of
// a ray's start, their mean dt past it.
double crossing_share_ahead(double dt, double spread);
// One level: a coverage table and its lattice. (SubRayShape reads the lattice asked for, and
// its table only as a CSG leaf: there null where none is read.)
struct FilterLevel {
    std::shared_ptr<const LatticeTable> table;
    TableContext ctx;
};

class FilteredLatticeShape final : public Shape, public CullParts, public SheetSource {
public:
    // levels: coarse to fine, the same box, cells doubling; every table has coverage (a null
    // one is refused). table_error: Encoding::error_bound of the finest level. box_shadows:
    // shadow rays read the box filter's one pair whatever `filter` (camera rays keep it).
    FilteredLatticeShape(std::vector<FilterLevel> levels, LatticeFilter filter,
                         double table_error, bool box_shadows = false);

    // The lattice box.
    Bounds3 bounds() const override { return bounds_; }
    // The whole footprint as one sheet.
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    // Shadow rays that need transmittance ask intersect for the coverage; as an any-hit test, a
    // sheet occludes when it covers at least half.
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    // A camera ray's pairs grouped by depth (kSheetDepthFootprints), a sheet a group, front to
    // back, each with the coverage that composites (LayerComposite) to its own share; a shadow
    // ray's one sheet.
    int sheets(const Ray& r, double tmin, double tmax,
               std::span<SheetCrossing, kMaxSheets> out) const override;
    // As a CSG leaf: the finest level point-sampled.
    void spans(const Ray& r, SpanList& out) const override;
    // The mean of unit normals: of length 1 or less (see intersect).
    Vec3 normal(const Ray&, const Crossing& c) const override { return c.stored.n; }
    bool inside(Vec3 p) const override;
    // Culled by the frame of level cull_level_ (see the constructor).
    std::size_t cull_count() const override { return cull_frame().cull_count(); }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double) const override {
        return cull_frame().cull_bounds(i, xf);
    }
    bool cull_meets(std::size_t i, const Ray& r) const override {
        return cull_frame().cull_meets(i, r);
    }
    bool cull_meets_any(const Ray& r) const override { return cull_frame().cull_meets_any(r); }
    bool cull_capsule(std::size_t i, const Transform& xf, double, Capsule& out) const override {
        return cull_frame().cull_capsule(i, xf, out);
    }
    // How far a ray leaving a sheet skips this lattice: a sheet's point is a blend of the
    // tables' pairs' points, within about 2 cells of the surface (of the coarsest level, whose
    // blends reach farthest).
    double surface_tolerance() const override { return span_tolerance(); }
    // Spans are the finest level's, point-sampled: its sheets' 2 cells of the coarsest level,
    // as the sheets'.
    double span_tolerance() const override { return 2.0 * levels_.front().frame.cell(); }

private:
    struct Level {
        std::shared_ptr<const LatticeTable> table;
        LatticeFrame frame;
        BoundaryGrid grid;
    };
    // A sheet: coverage-weighted sums of the pairs' points (primitive units) and normals, and,
    // when asked (keep_pairs), each pair's share of them (for sheets: at most 5 pairs a level,
    // 2 levels). Plain doubles, left unset until written: a Sheet is made for every ray.
    struct PairPart {
        double a, p[3], n[3];
    };
    static constexpr int kMaxPairParts = 10;
    struct Sheet {
        double alpha = 0;
        Vec3 p, n;
        bool keep_pairs = false;
        int pairs = 0;
        PairPart part[kMaxPairParts];
        void add(double w, const CoverageHit& h, const Vec3& p_prim) {
            const double a = w * h.alpha;
            alpha += a;
            p += p_prim * a;
            n += h.normal * a;
            if (!keep_pairs) return;
            assert(pairs < kMaxPairParts);  // Blend::kMaxPairs a level, two levels
            part[pairs++] = {a, {p_prim.x, p_prim.y, p_prim.z}, {h.normal.x, h.normal.y, h.normal.z}};
        }
    };
    // A sheet's pairs whose crossings lie within a depth of each other: the sums of their
    // shares, points and normals, as in Sheet.
    struct Cluster {
        double alpha = 0;
        Vec3 p, n;
    };
    // s's kept pairs in clusters, in ray order: each holds the pairs within `depth` (parameter
    // t of r) of its nearest. Returns how many (at most s.pairs).
    static int depth_clusters(const Sheet& s, const Ray& r, double depth, Cluster* out);
    // The level of detail a ray reads: `level` (0 to the finest, fractional between two) and how
    // many levels finer than the finest table its footprint is (`finer`).
    struct Lod {
        double width, level, finer;
    };
    Lod lod_of(const Ray& r) const;
    // s's pairs grouped by depth into sheets (see sheets and kMinSheetShare).
    int split(const Sheet& s, const Lod& lod, const Ray& r, double tmin, double tmax,
              std::span<SheetCrossing, kMaxSheets> out) const;
    // The pairs of one level that a ray's sheet blends, and their weights.
    struct Blend {
        static constexpr int kMaxPairs = 5;
        int n = 0;
        std::uint32_t ia[kMaxPairs], ib[kMaxPairs];
        std::uint64_t ref[kMaxPairs];  // the pairs located in the table (locate_coverage)
        GridPoint ca[kMaxPairs], cb[kMaxPairs];
        double w[kMaxPairs];
        void add(const BoundaryGrid& g, const GridPoint& a, const GridPoint& b, double weight) {
            add(g.id(a), g.id(b), a, b, weight);
        }
        // The same for points whose ids are known.
        void add(std::uint32_t id_a, std::uint32_t id_b, const GridPoint& a, const GridPoint& b,
                 double weight) {
            if (id_a != id_b) ia[n] = id_a, ib[n] = id_b, ca[n] = a, cb[n] = b, w[n] = weight, ++n;
        }
    };
    std::vector<Level> levels_;
    std::size_t cull_level_ = 0;
    LatticeFilter filter_;
    Bounds3 bounds_;
    // Shadow rays read the pair they snap to (the box filter), not the smooth filter's 5: for a
    // primitive costlier than kMaxExactCost (answer_plan), where lookups dominate the time
    // (docs/filtering.md, "Costly primitives"; figures in bench/notes/complexity-log.md).
    bool box_shadows_ = false;
    std::optional<HitTableShape> point_;  // the finest level, point-sampled

    const LatticeFrame& cull_frame() const { return levels_[cull_level_].frame; }
    // The lattice box (primitive units), the same at every level.
    const Bounds3& box() const { return levels_.back().frame.box(); }
    // The ray's footprint's width at the box (primitive units; 0 without one).
    double footprint_width(const Ray& r) const;
    // intersect, with or without the sheet's normal.
    bool sheet(const Ray& r, double tmin, double tmax, bool normal, Crossing& hit) const;
    // A sheet as r's crossing, if within (tmin, tmax); finer: how many levels finer than the
    // finest table the footprint is.
    bool to_crossing(const Sheet& s, double finer, const Ray& r, double tmin, double tmax,
                     bool normal, Crossing& hit) const;
    void blend(const Level& l, const Ray& r, double weight, bool smooth, Blend& b) const;
    // Looks the blend's pairs up and adds those that r meets after tmin to the sheet.
    void add_blend(const Level& l, const Blend& b, bool normals, const Ray& r, double tmin,
                   Sheet& s) const;
    // Adds the levels' blends around `level` (0 to the finest).
    void add_tables(double level, bool normal, const Ray& r, double tmin, Sheet& s) const;
};

}  // namespace lat
