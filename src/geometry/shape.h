#pragma once
// The solid-shape interface: every leaf of the scene (quartic, sphere, sphere/cylinder chain,
// lattice instance) and every CSG tree implements it in its own coordinates. It holds only
// geometry: what the accelerator, lattice tables and coverage ask besides, a shape offers
// through the opt-in interfaces named at the end of the class.
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
// The sphere around a box.
inline BoundingSphere sphere_around(const Bounds3& b) {
    return {b.center(), 0.5 * length(b.extent())};
}

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
    // The bounds of the shape placed by xf; round shapes override this to be tighter than the
    // box around the transformed box.
    virtual Bounds3 placed_bounds(const Transform& xf) const { return xf.bounds(bounds()); }
    // What else a shape can do is offered through opt-in interfaces, asked for where needed:
    // Parts and CullParts (geometry/parts.h) for the accelerator, LatticeSource and Pieces
    // (geometry/lattice_source.h) for lattice tables and CSG, SheetSource (coverage/sheets.h)
    // for partial coverage.
};

// Spans from `first` on, possibly overlapping: sorted and merged into their union.
void merge_span_union(SpanList& spans, std::size_t first);

// The first crossing of a span list with tmin < t < tmax, if any.
bool first_crossing(const SpanList& spans, double tmin, double tmax, Crossing& hit);

// For a ray starting on (or within rounding of) the shape's boundary: the crossing of its line
// nearest the start, moved to t = 0, so that normal() gives the surface there.
Crossing nearest_crossing(const Shape& shape, const Ray& r);

}  // namespace lat
