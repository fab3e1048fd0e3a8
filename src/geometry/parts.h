#pragma once
// What the accelerator asks of a shape beyond its geometry, as opt-in interfaces: a shape made
// of many parts (a chain's spheres and cylinders, a mesh's triangles) offers Parts, so that the
// hierarchy is built over them; a shape answered as a whole but hugging a thin primitive (a
// lattice) offers CullParts, regions the accelerator prunes rays with. The free functions
// below answer for every shape, with the defaults of a shape that offers neither: one part,
// the shape itself, culled by its bounds.
#include <cstddef>
#include <vector>

#include "geometry/shape.h"

namespace lat {

class Parts {
public:
    virtual std::size_t part_count() const = 0;
    // Part i's bounds, in the shape's coordinates and placed by xf.
    virtual Bounds3 part_bounds(std::size_t i) const = 0;
    virtual Bounds3 part_bounds(std::size_t i, const Transform& xf) const = 0;
    // Part i alone, as Shape::intersect, occluded and spans answer for the whole.
    virtual bool intersect_part(std::size_t i, const Ray& r, double tmin, double tmax,
                                Crossing& hit) const = 0;
    virtual bool occluded_part(std::size_t i, const Ray& r, double tmin, double tmax) const = 0;
    virtual void part_spans(std::size_t i, const Ray& r, SpanList& out) const = 0;
    // Spheres that together enclose part i (for culling by cones, as rasterization does).
    // Long parts give several smaller spheres.
    virtual void part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const = 0;
    // A capsule holding part i, when the shape knows one (chains do): lattices cull with
    // them, grown by how far their answers can stray.
    virtual bool part_capsule(std::size_t, Capsule&) const { return false; }

protected:
    ~Parts() = default;
};

// Culling parts: regions the accelerator prunes rays with, for shapes it answers as a whole. A
// ray gets a crossing from the shape only if its line meets one of them, and a shadow ray is
// occluded only if it does.
class CullParts {
public:
    virtual std::size_t cull_count() const = 0;
    // The bounds of cull part i placed by xf. widest: the widest footprint (shape units) of the
    // rays this placement is traced with (AccelObject::widest_footprint; infinity: any). A shape
    // whose reach grows with the footprint (a lattice's sub-rays) culls narrower for narrower
    // ones; its queries then take the same bound from their ray's footprint.
    virtual Bounds3 cull_bounds(std::size_t i, const Transform& xf, double widest) const = 0;
    // Whether the line of r (shape coordinates) can meet cull part i, for a line that meets its
    // bounds: a cheap test that saves the shape's own.
    virtual bool cull_meets(std::size_t i, const Ray& r) const = 0;
    // Whether cull_meets(i, r) holds for some i: for an object entered whole, whose box is
    // that of all its parts.
    virtual bool cull_meets_any(const Ray& r) const {
        for (std::size_t i = 0; i < cull_count(); ++i)
            if (cull_meets(i, r)) return true;
        return false;
    }
    // A capsule that every line cull_meets(i, .) accepts meets, placed by xf (world space), if
    // the cull part has one: the accelerator rejects rays by it before mapping them into the
    // shape's space. widest as for cull_bounds.
    virtual bool cull_capsule(std::size_t, const Transform&, double /*widest*/, Capsule&) const {
        return false;
    }

protected:
    ~CullParts() = default;
};

// The shape's interfaces, if it offers them (asked once per shape or object, not per ray).
inline const Parts* parts_of(const Shape& s) { return dynamic_cast<const Parts*>(&s); }
inline const CullParts* cull_parts_of(const Shape& s) { return dynamic_cast<const CullParts*>(&s); }

// Any shape's parts: its Parts, or the shape itself as one part. A small value, made once per
// shape (not per ray); its members answer as Parts' do.
class ShapeParts {
public:
    explicit ShapeParts(const Shape& s) : shape_(&s), parts_(parts_of(s)) {}
    // With the shape's Parts already asked (parts_of; null: it has none).
    ShapeParts(const Shape& s, const Parts* parts) : shape_(&s), parts_(parts) {}

    const Shape& shape() const { return *shape_; }
    // Null for a shape of one part.
    const Parts* parts() const { return parts_; }
    // The shape's own, so that loops written for a chain's concrete type take any shape.
    bool inside(Vec3 p) const { return shape_->inside(p); }
    Vec3 normal(const Ray& r, const Crossing& c) const { return shape_->normal(r, c); }
    std::size_t part_count() const { return parts_ ? parts_->part_count() : 1; }
    Bounds3 part_bounds(std::size_t i) const {
        return parts_ ? parts_->part_bounds(i) : shape_->bounds();
    }
    Bounds3 part_bounds(std::size_t i, const Transform& xf) const {
        return parts_ ? parts_->part_bounds(i, xf) : shape_->placed_bounds(xf);
    }
    bool intersect_part(std::size_t i, const Ray& r, double tmin, double tmax, Crossing& hit) const {
        return parts_ ? parts_->intersect_part(i, r, tmin, tmax, hit)
                      : shape_->intersect(r, tmin, tmax, hit);
    }
    bool occluded_part(std::size_t i, const Ray& r, double tmin, double tmax) const {
        return parts_ ? parts_->occluded_part(i, r, tmin, tmax) : shape_->occluded(r, tmin, tmax);
    }
    void part_spans(std::size_t i, const Ray& r, SpanList& out) const {
        if (parts_) parts_->part_spans(i, r, out);
        else shape_->spans(r, out);
    }
    // A shape of one part: the spheres of its LatticeSource, else the sphere around its box
    // (asked per call: culling spheres are made once, while a table is set up).
    void part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const;
    bool part_capsule(std::size_t i, Capsule& out) const {
        return parts_ && parts_->part_capsule(i, out);
    }

private:
    const Shape* shape_;
    const Parts* parts_;
};

// Any shape's cull parts: its CullParts, or one, its placed bounds, met by every line.
class ShapeCull {
public:
    explicit ShapeCull(const Shape& s) : shape_(&s), cull_(cull_parts_of(s)) {}
    // With the shape's CullParts already asked (cull_parts_of; null: it has none).
    ShapeCull(const Shape& s, const CullParts* cull) : shape_(&s), cull_(cull) {}

    std::size_t cull_count() const { return cull_ ? cull_->cull_count() : 1; }
    Bounds3 cull_bounds(std::size_t i, const Transform& xf, double widest) const {
        return cull_ ? cull_->cull_bounds(i, xf, widest) : shape_->placed_bounds(xf);
    }
    bool cull_meets(std::size_t i, const Ray& r) const { return !cull_ || cull_->cull_meets(i, r); }
    bool cull_capsule(std::size_t i, const Transform& xf, double widest, Capsule& out) const {
        return cull_ && cull_->cull_capsule(i, xf, widest, out);
    }

private:
    const Shape* shape_;
    const CullParts* cull_;
};

// The first crossing in (tmin, tmax) of the union of the listed parts of s, each intersected
// with intersect_part in list order (ties go to the earlier part). S: the shape's own type
// where the caller knows it, so that its parts' tests inline.
template <class S, class List>
bool first_crossing_of_parts(const S& s, const List& parts, const Ray& r, double tmin,
                             double tmax, Crossing& hit) {
    bool found = false;
    for (const auto part : parts) {
        Crossing c;
        if (s.intersect_part(part, r, tmin, tmax, c)) tmax = c.t, hit = c, found = true;
    }
    return found;
}

// Whether any of the listed parts of s blocks r within (tmin, tmax) (occluded_part).
template <class S, class List>
bool any_part_occludes(const S& s, const List& parts, const Ray& r, double tmin, double tmax) {
    for (const auto part : parts)
        if (s.occluded_part(part, r, tmin, tmax)) return true;
    return false;
}

}  // namespace lat
