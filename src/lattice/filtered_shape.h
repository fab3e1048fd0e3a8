#pragma once
// A lattice rendered through its prefiltered tables (issue 10; tables with Encoding::coverage).
// A ray gets one "sheet" from the lattice: a point, a normal and a coverage alpha, the share of
// the rays around it that meet the primitive. The renderer shades alpha of it and lets the ray
// go on behind for the rest (render/layers.h). Filters:
//   box     the coverage of the pair the ray snaps to (constant over the pair's cells);
//   smooth  the coverages of the 5 pairs around the ray's real entry and exit points, blended
//           linearly over a simplex of the 4-D (entry, exit) grid: continuous in ray space.
// Levels of detail: tables of the same box at sigma^-1 doubling from level to level; each ray
// takes the level whose cell matches its footprint (ray_footprint()), blending the two nearest.
// The primitive itself is the level after the finest table: its exact crossings are blended
// into every camera ray's answer, and into shadow rays' past the finest table (exact_weight).
// As a CSG leaf, for `inside` and for spans, the lattice is point-sampled through the finest
// level's own hits, exactly as without filtering.
#include <algorithm>
#include <memory>
#include <string_view>
#include <vector>

#include "lattice/hit_table_shape.h"
#include "lattice/part_boxes.h"

namespace lat {

enum class LatticeFilter { kNone, kBox, kSmooth };
// The option names, "none", "box" and "smooth": the one place they are spelled.
inline constexpr std::array<std::pair<std::string_view, LatticeFilter>, 3> kLatticeFilterNames{
    {{"none", LatticeFilter::kNone}, {"box", LatticeFilter::kBox}, {"smooth", LatticeFilter::kSmooth}}};

// The footprint of the ray being traced, which picks the level of detail: its width (world
// units) is width0 + spread * t at ray parameter t (world rays have unit directions). Set by the
// renderer per ray on its thread, so that the shape interface (Embree's callbacks) stays as it
// is; 0 (the default) asks for the finest level.
struct RayFootprint {
    double width0 = 0, spread = 0;
    // The ray wants only each sheet's coverage and where it lies (a shadow ray's transmittance):
    // the normals are not decoded, and the crossing's normal faces the ray.
    bool coverage_only = false;
};
void set_ray_footprint(const RayFootprint& f);
const RayFootprint& ray_footprint();

// A level's cell is made this many footprints wide: the box over a cell, widened by the smooth
// filter's linear blend, then matches a pixel's box best (Plate 4 at 512^2: 0.7, 0.85, 1.0 and
// 1.2 gave 35.9, 36.0, 35.8 and 34.9 dB against the 256-spp exact image, with shadow rays
// that missed the hairs they started in). Retuned once those were fixed, on six fur scenes
// (docs/filtering.md): 0.78 against 0.85, -0.01 to +0.25 dB on each; 0.7 lost 0.3 dB on one.
inline constexpr double kCellPerFootprint = 0.78;
// The level (real; 0 is the lattice of cell cell0, each next one halves it) for a footprint of
// this width, in the same units.
double lod_level(double cell0, double width);
// Levels are blended only within a band of this width around the midpoint between two (as
// "brilinear" texture filtering does): elsewhere a ray reads one level, half the lookups of a
// blend. Plate 4 (512^2, 1 spp, against 256-spp exact): a band of 1 (linear blending across
// the whole interval) 36.04 dB, 1/2 35.92 dB, 1/4 35.89 dB in 0.75 of its time, 0 (the
// nearest level) 35.88 dB in 0.70; the loss is all in shadow rays. 1/4 keeps changes of level
// across an image from showing as seams.
inline constexpr double kLodBlendBand = 0.25;
// The weight of the finer of two levels at fraction f (0 to 1) of the way to it.
double lod_blend(double f, double band);
// With levels of detail, the primitive itself is the level after the finest table (the finest
// built: at most 4K): a ray's sheet blends the primitive's own crossings (exact, full coverage)
// with the tables' answer, at weight exact_weight(past, mode), `past` being how many levels
// beyond the finest table's the ray's level (lod_level) lies. The tables blur edges and
// highlights over a cell (several pixels wide in close-ups, where the finest table is
// coarser than the footprint); exact crossings at 1 spp are sharp but aliased; the two errors
// differ enough that their blend beats both.
//   Camera rays take the crossings of 2 x 2 sub-rays across their footprint (add_exact), at
//   half weight wherever the tables match the footprint, rising to all of it at 2 levels past
//   the finest table. Half at every level makes a ray's answer independent of which levels
//   the scene's other instances made the finest (a ramp tied to the finest level was not), and
//   was as good or better: 1 spp, PSNR against 256-spp exact (64 for the furry bunny and
//   grass), Plates 2 / 3 / 4 / 5, bunny, grass (exact 4 spp: 44.45 / 52.81 / 36.92 / 39.46 /
//   31.03 / 35.73 dB); no exact crossings: 39.68 / 43.12 / 38.55 / 39.38 / 31.62 / 37.60; a
//   ramp from 0 at 2 levels before the finest to 1 at 2 past: 45.98 / 51.64 / 39.35 / 40.33 /
//   32.61 / 38.03; half, rising from 1 to 3 past: 45.52 / 51.52 / 39.35 / 40.32 / 33.01 /
//   38.45; half, rising from 0 to 2 past (kept): 45.98 / 51.64 / 39.35 / 40.33 / 33.01 / 38.45
//   (docs/filtering.md, "The primitive as the level after the finest table"). One crossing a
//   ray instead of sub-rays lost (Plate 5 39.26 dB over a ramp [-1, 3]): the sub-rays'
//   coverage antialiases edges at the pixel's own scale.
//   Shadow rays, which want only the coverage, take their own crossing, from 0 at 1 level
//   past the finest to all at 3: sub-rays for them changed no PSNR, and starting at -1 cost
//   Plate 5 0.09 dB in 12 % more time; without them Plates 2 and 3 lost 1.1 and 2 dB.
struct ExactMode {
    double base;      // the weight at and before `from`
    double from, to;  // levels past the finest table where the weight rises from base to 1
    int sub_rays;     // a side: sub_rays^2 crossings across the footprint
};
inline constexpr ExactMode kCameraExact{0.5, 0, 2, 2}, kShadowExact{0, 1, 3, 1};
static_assert(kCameraExact.from < kCameraExact.to && kShadowExact.from < kShadowExact.to);
// The weight of the primitive's crossings for a ray `past` levels beyond the finest table.
inline double exact_weight(double past, const ExactMode& mode) {
    const double rise = std::clamp((past - mode.from) / (mode.to - mode.from), 0.0, 1.0);
    return mode.base + (1 - mode.base) * rise;
}
// Primitives whose exact intersection costs more than this many simple tests
// (Shape::intersect_cost) are answered by their tables alone: a chain tests part after part,
// 4 times a camera ray, which is what the lattice of a tuft of 2,000 parts is there to spare.
inline constexpr double kMaxExactCost = 64;
// Unions of at most this many parts find the parts near a ray first (PartBoxes::near_parts).
inline constexpr std::size_t kMaxNearParts = 64;

// One level: a coverage table and its lattice.
struct FilterLevel {
    std::shared_ptr<const LatticeTable> table;
    TableContext ctx;
};

class FilteredLatticeShape final : public Shape {
public:
    // levels: coarse to fine, the same box, cells doubling; every table has coverage; the
    // primitive (ctx.primitive) must outlive the shape. table_error: Encoding::error_bound of
    // the finest level. exact_blend: rays blend in the primitive's crossings (exact_weight;
    // levels of detail on), if its intersect_cost is at most kMaxExactCost.
    FilteredLatticeShape(std::vector<FilterLevel> levels, LatticeFilter filter, double table_error,
                         bool exact_blend = false);

    Bounds3 bounds() const override { return point_.bounds(); }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    // Shadow rays that need transmittance ask intersect for the coverage; as an any-hit test, a
    // sheet occludes when it covers at least half.
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override { point_.spans(r, out); }
    // The mean of unit normals: of length 1 or less (see intersect).
    Vec3 normal(const Ray&, const Crossing& c) const override { return c.stored.n; }
    bool inside(Vec3 p) const override { return point_.inside(p); }
    // Culled by the frame of level cull_level_ (see the constructor).
    std::size_t cull_count() const override { return cull_frame().cull_count(); }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf) const override {
        return cull_frame().cull_bounds(i, xf);
    }
    bool cull_meets(std::size_t i, const Ray& r) const override {
        return cull_frame().cull_meets(i, r);
    }
    double surface_tolerance() const override { return 2.0 * levels_.front().frame.cell(); }

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
    const Shape* primitive_;  // its crossings are blended in when exact_blend_
    bool exact_blend_;
    // A union's parts' boxes: a sub-ray is intersected with the parts whose box it meets only.
    std::unique_ptr<const PartBoxes> part_boxes_;
    HitTableShape point_;  // the finest level, point-sampled

    const LatticeFrame& cull_frame() const { return levels_[cull_level_].frame; }
    // intersect, with or without the sheet's normal.
    bool sheet(const Ray& r, double tmin, double tmax, bool normal, Crossing& hit) const;
    void blend(const Level& l, const Ray& r, double weight, bool smooth, Blend& b) const;
    // Looks the blend's pairs up and adds those that r meets after tmin to the sheet.
    void add_blend(const Level& l, const Blend& b, bool normals, const Ray& r, double tmin,
                   Sheet& s) const;
    // Adds the levels' blends around `level` (0 to the finest), at weight `weight` in all.
    void add_tables(double level, double weight, bool normal, const Ray& r, double tmin,
                    Sheet& s) const;
    // Adds the primitive's own crossings of r past tmin, at weight `weight` in all (see the
    // definition); width: the ray's footprint at the box, primitive units; sub_rays a side.
    void add_exact(double weight, double width, int sub_rays, bool normal, const Ray& r,
                   double tmin, Sheet& s) const;
};

}  // namespace lat
