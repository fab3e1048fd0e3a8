#pragma once
// A primitive answered by its own crossings of sub-rays across each ray's footprint, read
// through its lattice's frame (for culling) but from no table: exact mode's footprint filtering
// answers every instanced primitive so, auto mode those its plan gives sub-rays
// (lattice/answer_plan.h). A ray gets at most kMaxSheets sheets: points, normals and coverages,
// the share of its sub-rays that meet the primitive there; the renderer shades each and lets
// the ray go on behind for the rest (coverage/layers.h).
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "coverage/sheets.h"
#include "coverage/sub_rays.h"
#include "geometry/chain.h"
#include "geometry/parts.h"
#include "lattice/hit_table_shape.h"
#include "lattice/part_boxes.h"

namespace lat {

struct RayQuad;
struct QuadCrossings;

// A ray with a footprint is answered by the crossings of kExactSubRays^2 sub-rays parallel to
// it across its footprint: the pixel's box filter on this primitive, as exact mode at that
// many samples would give, but shaded once a sheet. A ray without a footprint gets its own
// line's crossing.
//   Why 2 x 2: where intersecting the primitive is cheap, its sub-rays give a better image
// than the tables in less time at every footprint tried; 3 x 3 costs about twice the time for
// little gain, and one sub-ray is point sampling (bench/notes/filtering-constants.md).
inline constexpr int kExactSubRays = 2;
static_assert(kExactSubRays * kExactSubRays == kSubRays);
static_assert(kSubRays <= kMaxSheets, "a sheet per sub-ray at most");
// A camera ray's sub-rays that meet the primitive within this many footprint widths (along the
// ray) of the nearest one make one sheet, shaded once at their mean point; those farther make
// sheets of their own, each shaded with its own shadow rays. One sheet for them all would shade
// a tuft's strands one behind another, and shadow them from the light, at a point between
// them (the value: bench/notes/filtering-constants.md).
inline constexpr double kSheetDepth = 1;
// How far from a ray its farthest sub-ray lies, for a footprint this wide.
double farthest_sub_ray(double width);

class SubRayShape final : public Shape, public SheetSource, public CullParts {
public:
    // ctx: the lattice (box and cells) whose frame culls, and the primitive (ctx.primitive,
    // which must outlive the shape). table: the lattice's point-sampled table, which answers
    // as a CSG leaf (spans, `inside`; table_error its Encoding::error_bound), or null (the
    // primitive answers). width: the widest footprint (primitive units) the sub-rays span,
    // above 0: rays' footprints are narrowed to it, which bounds how far from a ray its
    // sub-rays go and so how far culling must reach; each instance narrower still by its own
    // bound (cull_bounds, RayFootprint::widest).
    SubRayShape(const TableContext& ctx, std::shared_ptr<const LatticeTable> table,
                double table_error, double width);

    // The lattice box grown by the sub-rays' reach.
    Bounds3 bounds() const override { return bounds_; }
    // The whole footprint as one sheet.
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    // The sub-rays that meet the primitive within kSheetDepth of the nearest make the first
    // sheet, those within kSheetDepth of the nearest left the next, and so on; one sheet for
    // rays whose sub-rays do not compose with other lattices' (no world directions across).
    int sheets(const Ray& r, double tmin, double tmax,
               std::span<SheetCrossing, kMaxSheets> out) const override;
    // As an any-hit test, a sheet occludes when it covers at least half.
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    // As a CSG leaf: the table point-sampled, or the primitive's own.
    void spans(const Ray& r, SpanList& out) const override;
    // The mean of unit normals: of length 1 or less.
    Vec3 normal(const Ray&, const Crossing& c) const override { return c.stored.n; }
    bool inside(Vec3 p) const override;
    std::size_t cull_count() const override { return frame_.cull_count(); }
    // An instance whose rays span at most `widest` has its capsules and boxes narrowed by the
    // reach its sub-rays cannot use (unspanned_reach).
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double widest) const override {
        return frame_.cull_bounds(i, xf, unspanned_reach(widest));
    }
    // By the reach of the ray's own sub-rays.
    bool cull_meets(std::size_t i, const Ray& r) const override;
    bool cull_meets_any(const Ray& r) const override;
    bool cull_capsule(std::size_t i, const Transform& xf, double widest,
                      Capsule& out) const override {
        return frame_.cull_capsule(i, xf, out, unspanned_reach(widest));
    }
    // How far a ray leaving a sheet skips this lattice: a sheet's point is a mean of points on
    // the primitive across the footprint, within its width. The width, not a cell or two,
    // keeps the shadows strands of one tuft cast on each other (bench/notes).
    double surface_tolerance() const override { return width_; }
    // Spans are the table's, point-sampled: its sheets' 2 cells; without one, the primitive's.
    double span_tolerance() const override {
        return point_ ? 2.0 * frame_.cell() : primitive_->span_tolerance();
    }

private:
    // A sheet: the sums of its sub-rays' points (primitive units) and unit normals, weighted by
    // their share of the footprint.
    struct Sheet {
        double alpha = 0;
        Vec3 p, n;
        std::uint8_t sub_rays = 0;  // which sub-rays met the primitive
        void add(double w, const Vec3& p_prim, const Vec3& unit_normal) {
            alpha += w;
            p += p_prim * w;
            n += unit_normal * w;
        }
    };
    // The sub-rays' own answers (sub_ray_hits): bit k of `met`, whether sub-ray k met the
    // primitive; then at t[k] along r's parameter, at point p[k] (primitive units) with unit
    // normal n[k] (camera rays), or blocked (shadow rays: p[k] halfway along its blocked chord,
    // no normal).
    struct SubRayHits {
        unsigned met = 0;
        double t[kSubRays];
        Vec3 p[kSubRays], n[kSubRays];
    };

    const Shape* primitive_;
    LatticeFrame frame_;  // culls, with its parts grown by sub_ray_reach_
    double width_;          // the widest footprint its sub-rays span
    double sub_ray_reach_;  // how far from a ray its sub-rays lie, at most (culling's reach)
    Bounds3 bounds_;
    // A chain's parts' boxes: a sub-ray is intersected with the parts whose box it meets only.
    std::unique_ptr<const PartBoxes> part_boxes_;
    const ChainShape* chain_ = nullptr;  // primitive_, when it is a chain
    // Shadow rays through a primitive costlier than kMaxExactCost (not a chain) test two of
    // their sub-rays, each standing for its neighbour (blocked_pairs), not four.
    bool paired_shadows_ = false;
    std::optional<HitTableShape> point_;  // the table, point-sampled (if given)

    const Bounds3& box() const { return frame_.box(); }
    // The ray's footprint's width at the box (primitive units; 0 without one).
    double footprint_width(const Ray& r) const;
    // How much of sub_ray_reach_ the sub-rays of footprints at most `width` wide leave unused:
    // 0 at width_ and above (written so that rounding never makes it negative).
    double unspanned_reach(double width) const {
        return width < width_ ? sub_ray_reach_ - farthest_sub_ray(width) : 0.0;
    }
    // The whole footprint's sheet, with or without its normal.
    bool sheet(const Ray& r, double tmin, double tmax, bool normal, Crossing& hit) const;
    // The width of r's sub-rays' footprint (primitive units): its own, narrowed to the shape's
    // and the instance's bound (cull_bounds).
    double sub_ray_width(const Ray& r) const;
    // The sheet of h's sub-rays in `which`; their unit normals into `normals`, if given.
    static void add_sub_rays(const SubRayHits& h, unsigned which, Sheet& s,
                             SubRayNormals* normals = nullptr);
    // A sheet as r's crossing, if within (tmin, tmax).
    static bool to_crossing(const Sheet& s, const Ray& r, double tmin, double tmax, bool normal,
                            Crossing& hit);
    // The primitive's own crossings of r's sub-rays past tmin (see the definition); width: the
    // ray's footprint at the box, primitive units.
    void sub_ray_hits(double width, bool normal, const Ray& r, double tmin, double tmax,
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
