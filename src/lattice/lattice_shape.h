#pragma once
// A lattice instance's shape (paper 2.1, 3.2.2): rays are answered by the table, not by the
// primitive. In the primitive's coordinates the ray is scaled to lattice units, clipped to the
// box, and its entry and exit points are rounded to the nearest grid points on their faces
// (LatticeFrame::snap); the pair is then looked up. Two shapes do that, one per kind of table:
//   HitTableShape        the table stores the pair's hit (lattice/hit_table_shape.h);
//   CandidateTableShape  the table names the primitive's parts the ray can meet, which are
//                        intersected exactly with the real ray (lattice/candidate_table_shape.h).
#include <memory>
#include <optional>
#include <vector>

#include "geometry/capsule_screen.h"
#include "geometry/parts.h"
#include "geometry/shape.h"
#include "lattice/boundary_grid.h"
#include "lattice/table.h"

namespace lat {

// The box, its boundary grid, the snapping of rays to grid point pairs, and the parts a
// lattice is culled with (CullParts::cull_count): what both lattice shapes share.
class LatticeFrame {
public:
    // reach: how far from the primitive (primitive units) the ray's point at an answer can lie,
    // infinity when unknown, which culls with the lattice box alone. ctx.primitive, when set,
    // lets the cull parts hug the primitive. beyond_box: how far outside the box a ray's line
    // can pass and still be answered (a filtered lattice's sub-rays); the cull parts are
    // clipped to the box grown by it.
    LatticeFrame(const TableContext& ctx, double reach, double beyond_box = 0);

    const Bounds3& box() const { return box_; }
    double cell() const { return cell_; }

    // See CullParts::cull_count, cull_bounds and cull_meets.
    // narrower: for rays known to need less reach, by how much (at most the reach) to narrow
    // the capsules and boxes (still around the parts grown by the rest, capsules being convex).
    std::size_t cull_count() const { return cull_.size(); }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double narrower = 0) const;
    bool cull_meets(std::size_t i, const Ray& r, double narrower = 0) const;
    // Whether cull_meets(i, r, narrower) holds for some i (the same answer, sooner).
    bool cull_meets_any(const Ray& r, double narrower = 0) const;
    // See CullParts::cull_capsule: a cull part of one capsule has it.
    bool cull_capsule(std::size_t i, const Transform& xf, Capsule& out, double narrower = 0) const;

    // The ray's line in lattice units, and its snapped entry and exit points.
    struct Snap {
        Vec3 o, d;                   // the ray, lattice units
        std::uint32_t a = 0, b = 0;  // grid point ids of the entry and exit points
        GridPoint pa, pb;
    };
    // False when the line misses the box. Snapped in float where a certified error bound
    // shows the answer is snap_double's (lattice/float_snap.h), else in double: the result is
    // snap_double's, bit for bit.
    bool snap(const Ray& r, Snap& s) const;
    // The reference: all in double (tests compare snap with it).
    bool snap_double(const Ray& r, Snap& s) const;

    // The line's chord through the box, in double: parameters of the ray (lattice units or
    // not: the same t), and the axes of the faces it enters and leaves by, and whether each
    // face is its axis's far one. False when the line misses the box.
    struct Chord {
        double t0 = 0, t1 = 0;
        int ax0 = -1, ax1 = -1;
        bool high0 = false, high1 = false;
    };
    bool chord(const Vec3& o, const Vec3& d, Chord& c) const;
    // A visit that wants the chord's real end points, not the snapped pair (the smooth filter):
    // the ray in lattice units (o, d, as snap's Snap has them) and its chord, counted as a
    // visit as snap counts one. The faces are snap's: snap_double takes them from this chord,
    // and snap's float path gives snap_double's answer.
    bool visit_chord(const Ray& r, Vec3& o, Vec3& d, Chord& c) const;

private:
    bool snap_points(Snap& s) const;  // from s.o and s.d, in double

    BoundaryGrid grid_;
    double cell_, inv_cell_;
    Bounds3 box_;  // primitive units
    // Culling, primitive units (see make_cull_parts): a box per part, and the capsules the
    // part's rays are tested against, capsules_[first, first + count), if any.
    static constexpr std::size_t kMaxCullParts = 16;
    struct CullPart {
        Bounds3 box;
        std::uint32_t first, count;
        // The primitive's parts in it, parts_[part_first, part_first + part_count): its world
        // bounds are also those of the placed parts grown by the reach (tight for turned
        // instances, where the box around the turned box is loose). None: the box alone.
        std::uint32_t part_first = 0, part_count = 0;
        // A half of a box split_in_halves cut: the whole box, the one grown by the reach on
        // every side (narrowing shrinks it, not the cut face). Empty: the box itself.
        Bounds3 whole = {};
    };
    std::vector<CullPart> cull_;
    std::vector<Capsule> capsules_;
    // All capsules_, when every cull part has some (cull_meets_any): most lines that meet an
    // instance's box miss its capsules, and the screen rejects them in float, four at once.
    CapsuleScreen screen_;
    std::vector<std::uint32_t> parts_;
    std::optional<ShapeParts> primitive_;  // its parts, when placed_parts bounds by them
    double reach_ = 0;
    // How much culling can be narrowed by: the reach, where the parts are clipped to the box
    // grown by at least as much (a filtered lattice's sub-rays), else 0: clipped to the box
    // itself, a narrowed box would lose the rays near its faces.
    double max_narrower_ = 0;
    // Placed bounds are computed per part and instance when the scene is built: only for
    // primitives of at most this many parts.
    static constexpr std::size_t kMaxPlacedParts = 256;

    struct CulledPart {  // one part of the primitive, as culling sees it
        Bounds3 box;
        Capsule capsule;
        double key = 0;
        std::uint32_t part = 0;
    };
    Bounds3 placed_parts(const CullPart& p, const Transform& xf, double narrower) const;
    void make_cull_parts(const Shape* primitive, double reach, const Bounds3& region);
    static void drop_covered(std::vector<CulledPart>& pieces);
    void group(const std::vector<CulledPart>& pieces, bool capsules, const Bounds3& region);
    void split_in_halves();
};

// The shape for a table of either kind; ctx.primitive must be set (candidate tables intersect
// it; both cull by it) and outlive the shape. hit_error: how far a stored hit can lie from the
// primitive (Encoding::error_bound), infinity when unknown.
std::shared_ptr<const Shape> make_lattice_shape(std::shared_ptr<const LatticeTable> table,
                                                const TableContext& ctx, double hit_error);

}  // namespace lat
