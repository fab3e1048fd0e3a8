#pragma once
// The solid-shape interface: every leaf of the scene (quartic, sphere, sphere/cylinder chain,
// lattice instance) and every CSG tree implements it in its own coordinates.
#include <cstdint>
#include <string_view>
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
    // The share of the rays around this one that meet the surface here (prefiltered lattices,
    // issue 10: a partial hit lets the rest of the ray go on behind it); 1 for every exact shape.
    // (In the padding after has_stored: a Crossing is no larger for it.)
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
    // Whether p is inside the solid (boundary counts as either).
    virtual bool inside(Vec3 p) const = 0;
    // Whether c's part (and CSG leaf) name a surface of this shape, so that normal() may be
    // asked for it: crossings read from files (lattice tables) are checked with it first.
    virtual bool names_surface(const Crossing& c) const { return c.part == 0; }

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

    // Boxes (shape coordinates) that the accelerator culls with: a ray gets a crossing from
    // this shape only at a point inside one of them (and a shadow ray is occluded only if it
    // passes through one). By default the bounds; a lattice gives a few boxes hugging its
    // primitive, much tighter than its lattice box.
    virtual void cull_boxes(std::vector<Bounds3>& out) const { out.push_back(bounds()); }

    // CSG trees carry a material tag per leaf; other shapes answer with the fallback.
    virtual std::uint32_t tag(const Crossing&, std::uint32_t fallback) const { return fallback; }
};

// Spans from `first` on, possibly overlapping: sorted and merged into their union.
void merge_span_union(SpanList& spans, std::size_t first);

// The first crossing of a span list with tmin < t < tmax, if any.
bool first_crossing(const SpanList& spans, double tmin, double tmax, Crossing& hit);

// For a ray starting on (or within rounding of) the shape's boundary: the crossing of its line
// nearest the start, moved to t = 0, so that normal() gives the surface there.
Crossing nearest_crossing(const Shape& shape, const Ray& r);

}  // namespace lat
