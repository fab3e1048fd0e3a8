#pragma once
// A lattice rendered through its prefiltered tables (tables with Encoding::coverage), or through
// the primitive's own crossings of sub-rays across each ray's footprint.
// A ray gets one "sheet" from the lattice: a point, a normal and a coverage alpha, the share of
// the rays around it that meet the primitive. The renderer shades alpha of it and lets the ray
// go on behind for the rest (render/layers.h). Filters:
//   box     the coverage of the pair the ray snaps to (constant over the pair's cells);
//   smooth  the coverages of the 5 pairs around the ray's real entry and exit points, blended
//           linearly over a simplex of the 4-D (entry, exit) grid: continuous in ray space.
// Levels of detail: tables of the same box at sigma^-1 doubling from level to level; each ray
// takes the level whose cell matches its footprint (Ray::footprint), blending the two nearest.
// Answered by the primitive's own crossings (exact_width above 0), it reads no table for rays:
// the sub-rays across each ray's footprint answer (kExactSubRays).
// As a CSG leaf, for `inside` and for spans, the lattice is point-sampled through the finest
// level's own hits, exactly as without filtering.
#include <algorithm>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "geometry/chain.h"
#include "geometry/sub_rays.h"
#include "lattice/hit_table_shape.h"
#include "lattice/part_boxes.h"

namespace lat {

struct RayQuad;
struct QuadCrossings;

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
// A primitive answered by its own crossings (auto mode for one answered_by_primitive, exact
// mode's footprint filtering for every one) answers each ray with a footprint by those of
// kExactSubRays^2 sub-rays parallel to the ray across its footprint (exact_sub_rays): for camera
// rays shaded once a sheet (those within kSheetDepth of each other) at their mean point with
// their own normals (the pixel's box filter on this primitive), for shadow rays their share as
// the coverage (a ray without a footprint: its own line's). Its table then serves CSG (spans,
// `inside`) only. A costly primitive in auto mode is answered by its tables and their levels,
// unless the levels its footprints want are past the build budget (render/scene_lattices.h):
// then by its crossings too, its shadow rays testing their sub-rays in pairs (blocked_pairs).
//   Why 2 x 2: where intersecting the primitive is cheap, its sub-rays give a better image than
// the tables in less time at every footprint tried; 3 x 3 gained 0.2 to 0.8 dB for 1.7 to 2.2
// times the time, and one sub-ray is point sampling (bench/notes/filtering-constants.md).
inline constexpr int kExactSubRays = 2;
static_assert(kExactSubRays * kExactSubRays == kSubRays);
static_assert(kSubRays <= Shape::kMaxSheets, "a sheet per sub-ray at most");
// A camera ray's sub-rays that meet the primitive within this many footprint widths (along the
// ray) of the nearest one make one sheet, shaded once at their mean point; those farther make
// sheets of their own, each shaded with its own shadow rays (sheets). One sheet for them all had
// a tuft's strands one behind another shaded, and shadowed from the light, at a point between
// them; 1 was best of 1, 2 and 4 on five fur scenes (bench/notes/filtering-constants.md).
inline constexpr double kSheetDepth = 1;
// How far from a ray its farthest sub-ray lies, for a footprint this wide.
double farthest_sub_ray(double width);
// Primitives other than chains whose exact intersection costs more than this many simple tests
// (Shape::intersect_cost) are answered by their tables in auto mode, when the levels their
// footprints want are within the build budget (render/scene_lattices.h, kMaxLodWork; else by
// their crossings): past it a sub-ray costs more than a table's blend of pairs, and the tables
// are ahead of exact mode at equal time (bench/notes/filtering-constants.md).
inline constexpr double kMaxExactCost = 64;
// Whether auto mode answers a primitive's rays from the primitive itself: a chain (spheres and
// cylinders: hairs, tufts) always, whatever its parts, since its sub-rays test only the parts
// near the ray, found through a tree of their boxes (PartBoxes), and were faster and more
// faithful than its tables from 200 to 10,000 parts; other shapes when they cost at most
// kMaxExactCost (bench/notes/filtering-constants.md).
bool answered_by_primitive(const Shape& primitive);

// One level: a coverage table and its lattice. The table may be null for a primitive answered
// by its own crossings (the shape then reads none; see spans and inside).
struct FilterLevel {
    std::shared_ptr<const LatticeTable> table;
    TableContext ctx;
};

class FilteredLatticeShape final : public Shape {
public:
    // levels: coarse to fine, the same box, cells doubling; every table has coverage (or is null:
    // FilterLevel); the primitive (ctx.primitive) must outlive the shape. table_error:
    // Encoding::error_bound of the finest level. exact_width: above 0, rays take the primitive's
    // own crossings (levels of detail on; one level), as scene_lattices decides (a primitive
    // answered_by_primitive, or one whose levels wanted are past the build budget); their
    // footprints are narrowed to at most exact_width (primitive units), which bounds how far from a
    // ray its sub-rays go and so how far culling must reach; each instance narrower still by its
    // own bound (cull_bounds, RayFootprint::widest). A ray without a footprint gets the crossing of
    // its own line.
    FilteredLatticeShape(std::vector<FilterLevel> levels, LatticeFilter filter, double table_error,
                         double exact_width = 0);

    // The lattice box, grown by the sub-rays' reach when the primitive answers.
    Bounds3 bounds() const override { return bounds_; }
    // The whole footprint as one sheet.
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    // Answered by the primitive's crossings: the sub-rays that meet it within kSheetDepth of
    // the nearest make the first sheet, those within kSheetDepth of the nearest left the next,
    // and so on. Otherwise intersect's one sheet.
    int sheets(const Ray& r, double tmin, double tmax,
               std::span<SheetCrossing, kMaxSheets> out) const override;
    // Shadow rays that need transmittance ask intersect for the coverage; as an any-hit test, a
    // sheet occludes when it covers at least half.
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    // As a CSG leaf: the finest level point-sampled; without a table (FilterLevel), the
    // primitive's own.
    void spans(const Ray& r, SpanList& out) const override;
    // The mean of unit normals: of length 1 or less (see intersect).
    Vec3 normal(const Ray&, const Crossing& c) const override { return c.stored.n; }
    bool inside(Vec3 p) const override;
    // Culled by the frame of level cull_level_ (see the constructor).
    std::size_t cull_count() const override { return cull_frame().cull_count(); }
    // An instance whose rays span at most `widest` has its capsules and boxes narrowed by the
    // reach its sub-rays cannot use (unspanned_reach).
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double widest) const override {
        return cull_frame().cull_bounds(i, xf, unspanned_reach(widest));
    }
    // With the primitive's crossings, by the reach of the ray's own sub-rays.
    bool cull_meets(std::size_t i, const Ray& r) const override;
    bool cull_capsule(std::size_t i, const Transform& xf, double widest,
                      Capsule& out) const override {
        return cull_frame().cull_capsule(i, xf, out, unspanned_reach(widest));
    }
    // How far a ray leaving a sheet skips this lattice: a sheet's point is a blend of the
    // tables' pairs' points, within about 2 cells of the surface; with the primitive's
    // crossings, a mean of points on it across the footprint, within its width. The sub-rays'
    // widest footprint, not 2 cells, keeps the shadows strands of one tuft cast on each other:
    // ball-tuft216 answered by sub-rays 30.72 dB with 2 cells, 32.72 with the width, 32.90 with
    // half of it (the furry bunny 32.71, 32.90, 32.66 dB; Plate 3 52.98, 53.15, 53.04; Plates 2,
    // 4, 5 and grass within 0.05 dB). The tables' own sheets want their 2 cells (the tuft's
    // tables: 31.01 dB with 2 cells, 30.97 with 1, 30.55 with 1/2).
    double surface_tolerance() const override { return exact_ ? exact_width_ : span_tolerance(); }
    // Spans are point_'s, point-sampled from a table: its sheets' 2 cells (of the coarsest
    // level, as for every filtered lattice before sub-rays); without one, the primitive's.
    double span_tolerance() const override {
        return point_ ? 2.0 * levels_.front().frame.cell() : primitive_->span_tolerance();
    }

private:
    struct Level {
        std::shared_ptr<const LatticeTable> table;
        LatticeFrame frame;
        BoundaryGrid grid;
    };
    // A sheet: coverage-weighted sums of the pairs' points (primitive units) and normals.
    struct Sheet {
        double alpha = 0;
        Vec3 p, n;
        std::uint8_t sub_rays = 0;  // add_sub_rays': which sub-rays met the primitive
        void add(double w, const CoverageHit& h, const Vec3& p_prim) {
            alpha += w * h.alpha;
            p += p_prim * (w * h.alpha);
            n += h.normal * (w * h.alpha);
        }
        void add_opaque(double w, const Vec3& p_prim, const Vec3& unit_normal) {
            alpha += w;
            p += p_prim * w;
            n += unit_normal * w;
        }
    };
    // The pairs of one level that a ray's sheet blends, and their weights.
    struct Blend {
        static constexpr int kMaxPairs = 5;
        int n = 0;
        std::uint32_t ia[kMaxPairs], ib[kMaxPairs];
        std::uint64_t ref[kMaxPairs];  // the pairs located in the table (locate_coverage)
        GridPoint ca[kMaxPairs], cb[kMaxPairs];
        double w[kMaxPairs];
        void add(const BoundaryGrid& g, const GridPoint& a, const GridPoint& b, double weight) {
            ia[n] = g.id(a), ib[n] = g.id(b);
            if (ia[n] != ib[n]) ca[n] = a, cb[n] = b, w[n] = weight, ++n;
        }
    };
    std::vector<Level> levels_;
    std::size_t cull_level_ = 0;
    LatticeFilter filter_;
    const Shape* primitive_;  // its crossings answer rays with a footprint when exact_
    bool exact_;
    double exact_width_;    // the widest footprint its sub-rays span
    double sub_ray_reach_;  // how far from a ray its sub-rays lie, at most (culling's reach)
    Bounds3 bounds_;
    // A chain's parts' boxes: a sub-ray is intersected with the parts whose box it meets only.
    std::unique_ptr<const PartBoxes> part_boxes_;
    const ChainShape* chain_ = nullptr;  // primitive_, when it is a chain
    // Shadow rays through a primitive costlier than kMaxExactCost (not a chain) test two of
    // their sub-rays, each standing for its neighbour (blocked_pairs), not four.
    bool paired_shadows_ = false;
    // Shadow rays through the tables of such a primitive read the pair they snap to (the box
    // filter), not the smooth filter's 5: on the burr of the costly-primitive bench (`ball-csg7`,
    // sigma^-1 = 4, 1 spp) 33.39 dB in 0.90 of exact 1 spp's time, against 34.50 dB in 1.09 with
    // smooth shadows (exact: 32.82 dB; docs/filtering.md, "Costly primitives").
    bool box_shadows_ = false;
    std::optional<HitTableShape> point_;  // the finest level, point-sampled (if it has a table)

    const LatticeFrame& cull_frame() const { return levels_[cull_level_].frame; }
    // The lattice box (primitive units), the same at every level.
    const Bounds3& box() const { return levels_.back().frame.box(); }
    // The ray's footprint's width at the box (primitive units; 0 without one).
    double footprint_width(const Ray& r) const;
    // How much of sub_ray_reach_ the sub-rays of footprints at most `width` wide leave unused:
    // 0 at exact_width_ and above, and for lattices answered by their tables (written so that
    // rounding never makes it negative).
    double unspanned_reach(double width) const {
        return exact_ && width < exact_width_ ? sub_ray_reach_ - farthest_sub_ray(width) : 0.0;
    }
    // The sub-rays' own answers (exact_sub_rays): bit k of `met`, whether sub-ray k met the
    // primitive; then at t[k] along r's parameter, at point p[k] (primitive units) with unit
    // normal n[k] (camera rays), or blocked (shadow rays: p[k] halfway along its blocked chord,
    // no normal).
    struct SubRayHits {
        unsigned met = 0;
        double t[kSubRays];
        Vec3 p[kSubRays], n[kSubRays];
    };
    // intersect, with or without the sheet's normal.
    bool sheet(const Ray& r, double tmin, double tmax, bool normal, Crossing& hit) const;
    // The width of r's sub-rays' footprint (primitive units): its own, narrowed to the shape's
    // and the instance's bound (cull_bounds).
    double sub_ray_width(const Ray& r) const;
    // The sheet of h's sub-rays in `which`; their unit normals into `normals`, if given.
    static void add_sub_rays(const SubRayHits& h, unsigned which, Sheet& s,
                             SubRayNormals* normals = nullptr);
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
    // The primitive's own crossings of r's sub-rays past tmin (see the definition); width: the
    // ray's footprint at the box, primitive units.
    void exact_sub_rays(double width, bool normal, const Ray& r, double tmin, double tmax,
                        SubRayHits& h) const;
    // The sub-rays' first crossings (the lanes found) and which of them are blocked, over the
    // parts near their ray (all of the primitive without part boxes).
    unsigned sub_ray_crossings(std::span<const std::uint32_t> parts, RayQuad& q, unsigned live,
                               QuadCrossings& hits) const;
    unsigned blocked_sub_rays(std::span<const std::uint32_t> parts, const RayQuad& q,
                              unsigned live) const;
    unsigned blocked_pairs(const RayQuad& q, unsigned live) const;
};

}  // namespace lat
