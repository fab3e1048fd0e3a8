#pragma once
// The solid-shape interface: every leaf of the scene (quartic, sphere, sphere/cylinder chain,
// lattice instance) and every CSG tree implements it in its own coordinates.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>
#include <vector>

#include "math/bounds.h"
#include "math/ray.h"
#include "math/transform.h"

namespace lat {

// Relative slack (of r^2) with which a ray counts as touching a round surface, so that exact
// tangencies (common on lattice grids) count as hits despite rounding.
inline constexpr double kTouchTolerance = 1e-9;

struct BoundingSphere {
    Vec3 center;
    double radius;
};

// The points within distance r of the segment [a, b] (a sphere when a = b).
struct Capsule {
    Vec3 a, b;
    double r;

    // Whether the line o + t d (d non-zero) comes within r of the segment. With w = o - a
    // and u = b - a projected across the line (pw, pu), the squared distance from the line to
    // a + s u is |s pu - pw|^2, minimised over s in [0, 1]; the interior case is compared
    // multiplied through by |pu|^2, so the one division is 1 / |d|^2 (lattice culling calls
    // this for every ray that meets a capsule's box).
    bool meets_line(Vec3 o, Vec3 d) const { return meets_line(o, d, r); }
    // The same, for the capsule of this segment and radius `radius`.
    bool meets_line(Vec3 o, Vec3 d, double radius) const {
        const double inv_dd = 1.0 / dot(d, d);
        const Vec3 w = o - a, u = b - a;
        const Vec3 pw = w - d * (dot(w, d) * inv_dd), pu = u - d * (dot(u, d) * inv_dd);
        const double uu = dot(pu, pu), wu = dot(pw, pu), ww = dot(pw, pw), rr = radius * radius;
        if (wu <= 0) return ww <= rr;                      // nearest at a
        if (wu >= uu) return uu - 2 * wu + ww <= rr;       // nearest at b
        return ww * uu - wu * wu <= rr * uu;               // nearest inside
    }
    // Whether c lies inside: both ends of its segment within r - c.r of this segment (the
    // distance to a segment is convex along c's segment).
    bool contains(const Capsule& c) const {
        const double slack = r - c.r;
        return slack >= 0 && distance_squared(c.a) <= slack * slack &&
               distance_squared(c.b) <= slack * slack;
    }
    double distance_squared(Vec3 p) const {
        const Vec3 u = b - a, w = p - a;
        const double uu = dot(u, u);
        const double s = uu > 0 ? std::clamp(dot(w, u) / uu, 0.0, 1.0) : 0.0;
        return length_squared(w - u * s);
    }
    // Its box under xf: the box of the placed segment grown by the placed ball's half-extents
    // (r times the length of each row of the linear part), exact for the swept ellipsoid.
    Bounds3 placed_bounds(const Transform& xf) const;
};

// A capsule in float (28 bytes: the accelerator keeps one a cull part) that holds a given one:
// its ends are rounded, and its radius grown by their rounding and rounded up. A line's test
// allows, besides, for the rounding of a far origin (1e-9 of its distance from the capsule),
// so that it accepts every line that the held capsule's test accepts on the same line mapped
// into another space, with its own rounding (LatticeFrame::cull_capsule).
struct FloatCapsule {
    float a[3] = {}, b[3] = {}, r = -1;  // r < 0: none, and every line meets it

    static FloatCapsule holding(const Capsule& c);
    bool meets_line(Vec3 o, Vec3 d) const {
        if (r < 0) return true;
        const auto wide = [](float f) { return static_cast<double>(f); };
        const Capsule c{{wide(a[0]), wide(a[1]), wide(a[2])}, {wide(b[0]), wide(b[1]), wide(b[2])},
                        wide(r)};
        return c.meets_line(o, d, c.r + 1e-9 * max_component(abs(o - c.a)));
    }
};

// A hit's place on its surface and the outward unit normal there.
struct SurfacePoint {
    Vec3 p, n;
};

// A point where a ray crosses a shape's boundary. `part` tells the shape which surface it was
// (so the normal can be computed later, only for the hit that is shaded); `leaf` names the
// CSG leaf, with kFlipBit set when the surface belongs to a subtracted solid. Shapes that learn
// the surface point together with the crossing (lattice tables, whose stored point lies near,
// not on, the ray) keep it in `stored`, so shading it needs no second lookup.
struct Crossing {
    static constexpr std::uint32_t kFlipBit = 1u << 31;

    Crossing() = default;
    Crossing(double t_, std::uint32_t part_, std::uint32_t leaf_) : t(t_), part(part_), leaf(leaf_) {}
    Crossing(double t_, std::uint32_t part_, const SurfacePoint& s)
        : t(t_), part(part_), has_stored(true), stored(s) {}

    double t = 0;
    std::uint32_t part = 0;
    std::uint32_t leaf = 0;
    bool has_stored = false;
    // Partial coverage (coverage/): of the ray's sub-rays (coverage/sub_rays.h), bit k when the
    // k-th meets the surface here, where the coverage is their share; 0 otherwise.
    std::uint8_t sub_rays = 0;
    // The share of the rays around this one that meet the surface here (lattices answered
    // through a footprint: a partial hit lets the rest of the ray go on behind it); 1 for every
    // exact shape. (Both in the padding after has_stored: a Crossing is no larger for them.)
    float coverage = 1.0f;
    SurfacePoint stored;  // when has_stored: in the coordinates of the shape that found it

    std::uint32_t leaf_index() const { return leaf & ~kFlipBit; }
    bool flipped() const { return (leaf & kFlipBit) != 0; }
};

// One interval of a ray's line inside a solid: enters at in.t, leaves at out.t (in.t < out.t).
// Unbounded solids give in.t = -infinity or out.t = +infinity.
struct Span {
    Crossing in, out;
};
using SpanList = std::vector<Span>;

class Shape {
public:
    virtual ~Shape() = default;

    // Bounds in the shape's coordinates; infinite for unbounded solids.
    virtual Bounds3 bounds() const = 0;

    // The closest boundary crossing with tmin < t < tmax.
    virtual bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const = 0;
    // Whether any boundary crossing has tmin < t < tmax (shadow rays).
    virtual bool occluded(const Ray& r, double tmin, double tmax) const {
        Crossing c;
        return intersect(r, tmin, tmax, c);
    }
    // Appends the intervals of the whole line r.o + t r.d, t in (-inf, inf), inside the solid:
    // sorted, disjoint and non-empty. Used by CSG.
    virtual void spans(const Ray& r, SpanList& out) const = 0;
    // Outward unit normal at a crossing this shape reported for ray r.
    virtual Vec3 normal(const Ray& r, const Crossing& c) const = 0;
    // The surface point and normal of a crossing this shape reported for ray r: the stored one
    // when the crossing carries it, else the ray's point and normal().
    virtual SurfacePoint surface(const Ray& r, const Crossing& c) const {
        return c.has_stored ? c.stored : SurfacePoint{r.at(c.t), normal(r, c)};
    }
    // Shadow rays leaving a surface point of this shape ignore this shape's crossings closer
    // than this (object units): zero for exact shapes, the table error for lattices.
    virtual double surface_tolerance() const { return 0.0; }
    // The same for the points of its spans, which a CSG tree with this shape as a leaf answers
    // with (they can come from elsewhere than its intersect's: a filtered lattice's).
    virtual double span_tolerance() const { return surface_tolerance(); }
    // Whether p is inside the solid (boundary counts as either).
    virtual bool inside(Vec3 p) const = 0;
    // Whether c's part (and CSG leaf) name a surface of this shape, so that normal() may be
    // asked for it: crossings read from files (lattice tables) are checked with it first.
    virtual bool names_surface(const Crossing& c) const { return c.part == 0; }
    // How many surfaces the leaf field of this shape's crossings can name, each with its own
    // normal and material (a CSG tree: one per surface of its leaves); 1 for shapes whose
    // crossings need no such name.
    virtual std::uint32_t surface_count() const { return 1; }
    // Whether normal() at c is a few flops (a plane, quadric, sphere or cylinder), not the
    // gradient of a quartic: `dense` tables store a hit's part, to re-evaluate its normal at
    // every lookup, only where that is cheap.
    virtual bool cheap_normal(const Crossing&) const { return true; }

    // About how many simple tests (a sphere's or a cylinder's) one intersect() makes: what a
    // lattice weighs before tracing its primitive exactly where its tables could answer
    // (lattice/answer_plan.h). By default its primitives, tested one by one.
    virtual double intersect_cost() const { return static_cast<double>(primitive_count()); }

    // Shapes made of many parts (sphere/cylinder chains) expose them so the accelerator can
    // build a hierarchy over them; by default the shape is one primitive.
    virtual std::size_t primitive_count() const { return 1; }
    virtual Bounds3 primitive_bounds(std::size_t) const { return bounds(); }
    // The bounds of a primitive placed by xf.
    virtual Bounds3 primitive_bounds(std::size_t, const Transform& xf) const {
        return placed_bounds(xf);
    }
    // The bounds of the shape placed by xf; round shapes override this to be tighter than the
    // box around the transformed box.
    virtual Bounds3 placed_bounds(const Transform& xf) const { return xf.bounds(bounds()); }
    virtual bool intersect_primitive(std::size_t, const Ray& r, double tmin, double tmax,
                                     Crossing& hit) const {
        return intersect(r, tmin, tmax, hit);
    }
    virtual bool occluded_primitive(std::size_t, const Ray& r, double tmin, double tmax) const {
        return occluded(r, tmin, tmax);
    }
    virtual void primitive_spans(std::size_t, const Ray& r, SpanList& out) const { spans(r, out); }

    // Spheres that together enclose primitive i (for culling by cones, as rasterization does);
    // by default the sphere around its box. Long parts give several smaller spheres.
    virtual void primitive_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
        const Bounds3 b = primitive_bounds(i);
        out.push_back({b.center(), 0.5 * length(b.extent())});
    }

    // A capsule holding primitive i, when the shape knows one (chains do): lattices cull with
    // them, grown by how far their answers can stray.
    virtual bool primitive_capsule(std::size_t, Capsule&) const { return false; }

    // Pieces: what an exact lattice (`candidates`) lists per grid-point pair, the pieces of the
    // shape that a ray near the pair's segment can meet; the others are switched off for the
    // ray. By default the pieces are the primitives and the shape is their union, so a listed
    // piece is intersected on its own (intersect_primitive). Shapes that are not the union of
    // their pieces (CSG: its leaves) say so and answer pieces_spans.
    virtual std::size_t piece_count() const { return primitive_count(); }
    // Spheres that together enclose the solid of piece i.
    virtual void piece_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
        primitive_spheres(i, out);
    }
    virtual bool pieces_are_union() const { return true; }
    // Appends the spans of r's whole line through the solid made of the pieces `on` (ascending)
    // with every other piece empty: the shape's own spans wherever the solids of the pieces
    // switched off are away from the line.
    virtual void pieces_spans(std::span<const std::uint32_t> on, const Ray& r, SpanList& out) const;

    // Culling parts: regions the accelerator prunes rays with, for shapes it answers as a whole
    // (a lattice gives parts hugging its primitive, much tighter than its lattice box). A ray
    // gets a crossing from this shape only if its line meets one of them, and a shadow ray is
    // occluded only if it does. By default one part, the bounds.
    virtual std::size_t cull_count() const { return 1; }
    // The bounds of cull part i placed by xf. widest: the widest footprint (shape units) of the
    // rays this placement is traced with (AccelObject::widest_footprint; infinity: any). A shape
    // whose reach grows with the footprint (a lattice's sub-rays) culls narrower for
    // narrower ones; its queries then take the same bound from their ray's footprint
    // (RayFootprint::widest).
    virtual Bounds3 cull_bounds(std::size_t, const Transform& xf, double /*widest*/) const {
        return placed_bounds(xf);
    }
    // Whether the line of r (shape coordinates) can meet cull part i, for a line that meets its
    // bounds: a cheap test that saves the shape's own.
    virtual bool cull_meets(std::size_t, const Ray&) const { return true; }
    // A capsule that every line cull_meets(i, .) accepts meets, placed by xf (world space), if
    // the cull part has one: the accelerator rejects rays by it before mapping them into the
    // shape's space (about half the rays meeting a cull part's box miss its capsule).
    // widest as for cull_bounds.
    virtual bool cull_capsule(std::size_t, const Transform&, double /*widest*/, Capsule&) const {
        return false;
    }

    // CSG trees carry a material tag per leaf; other shapes answer with the fallback.
    virtual std::uint32_t tag(const Crossing&, std::uint32_t fallback) const { return fallback; }
};

// Spans from `first` on, possibly overlapping: sorted and merged into their union.
void merge_span_union(SpanList& spans, std::size_t first);

// The first crossing in (tmin, tmax) of the union of the listed parts of s, each intersected
// with intersect_primitive in list order (ties go to the earlier part). S: the shape's own type
// where the caller knows it, so that its parts' tests inline.
template <class S, class Parts>
bool first_crossing_of_parts(const S& s, const Parts& parts, const Ray& r, double tmin,
                             double tmax, Crossing& hit) {
    bool found = false;
    for (const auto part : parts) {
        Crossing c;
        if (s.intersect_primitive(part, r, tmin, tmax, c)) tmax = c.t, hit = c, found = true;
    }
    return found;
}

// Whether any of the listed primitives of s blocks r within (tmin, tmax) (occluded_primitive).
template <class S, class Parts>
bool any_part_occludes(const S& s, const Parts& parts, const Ray& r, double tmin, double tmax) {
    for (const auto part : parts)
        if (s.occluded_primitive(part, r, tmin, tmax)) return true;
    return false;
}

// The first crossing of a span list with tmin < t < tmax, if any.
bool first_crossing(const SpanList& spans, double tmin, double tmax, Crossing& hit);

// For a ray starting on (or within rounding of) the shape's boundary: the crossing of its line
// nearest the start, moved to t = 0, so that normal() gives the surface there.
Crossing nearest_crossing(const Shape& shape, const Ray& r);

}  // namespace lat
