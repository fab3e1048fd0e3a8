#pragma once
// What lattice tables (and CSG trees) ask of the primitive they stand for, beyond its geometry,
// as opt-in interfaces: LatticeSource names its surfaces and weighs its tests; Pieces splits a
// shape that is not the union of its parts (a CSG tree: its leaves). ShapeSource answers for
// every shape, with the defaults of one that offers neither.
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/parts.h"
#include "geometry/shape.h"

namespace lat {

class LatticeSource {
public:
    // Whether c's part (and CSG leaf) name a surface of this shape, so that normal() may be
    // asked for it: crossings read from files (lattice tables) are checked with it first.
    virtual bool names_surface(const Crossing& c) const = 0;
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
    // (lattice/answer_plan.h).
    virtual double intersect_cost() const = 0;
    // Spheres that together enclose the solid, for a shape of one part, if it knows tighter
    // ones than the sphere around its box (a torus's ring of balls); false: it does not.
    virtual bool bounding_spheres(std::vector<BoundingSphere>&) const { return false; }

protected:
    ~LatticeSource() = default;
};

// Pieces: what an exact lattice (`candidates`) lists per grid-point pair, the pieces of the
// shape that a ray near the pair's segment can meet; the others are switched off for the ray.
// By default the pieces are the parts and the shape is their union, so a listed piece is
// intersected on its own (Parts::intersect_part). Shapes that are not the union of their
// pieces (CSG: its leaves) offer this.
class Pieces {
public:
    virtual std::size_t piece_count() const = 0;
    // Spheres that together enclose the solid of piece i.
    virtual void piece_spheres(std::size_t i, std::vector<BoundingSphere>& out) const = 0;
    // Appends the spans of r's whole line through the solid made of the pieces `on`
    // (ascending) with every other piece empty: the shape's own spans wherever the solids of
    // the pieces switched off are away from the line.
    virtual void pieces_spans(std::span<const std::uint32_t> on, const Ray& r,
                              SpanList& out) const = 0;

protected:
    ~Pieces() = default;
};

// Any shape as a lattice's primitive: its LatticeSource and Pieces where it offers them, else
// the defaults (surface 0 only, cheap normals, one test per part, pieces = parts). A small
// value, made once per shape.
class ShapeSource {
public:
    explicit ShapeSource(const Shape& s)
        : parts_(s), source_(dynamic_cast<const LatticeSource*>(&s)),
          pieces_(dynamic_cast<const Pieces*>(&s)) {}

    const Shape& shape() const { return parts_.shape(); }
    const ShapeParts& parts() const { return parts_; }

    bool names_surface(const Crossing& c) const {
        return source_ ? source_->names_surface(c) : c.part == 0;
    }
    std::uint32_t surface_count() const { return source_ ? source_->surface_count() : 1; }
    bool cheap_normal(const Crossing& c) const { return !source_ || source_->cheap_normal(c); }
    // By default its parts, tested one by one.
    double intersect_cost() const {
        return source_ ? source_->intersect_cost() : static_cast<double>(parts_.part_count());
    }

    bool pieces_are_union() const { return pieces_ == nullptr; }
    std::size_t piece_count() const { return pieces_ ? pieces_->piece_count() : parts_.part_count(); }
    void piece_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
        if (pieces_) pieces_->piece_spheres(i, out);
        else parts_.part_spheres(i, out);
    }
    // The union of the listed parts' spans where the shape is their union.
    void pieces_spans(std::span<const std::uint32_t> on, const Ray& r, SpanList& out) const;

private:
    ShapeParts parts_;
    const LatticeSource* source_;
    const Pieces* pieces_;
};

}  // namespace lat
