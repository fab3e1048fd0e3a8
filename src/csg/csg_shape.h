#pragma once
// Constructive solid geometry (paper 3.1): a tree whose leaves are shapes and whose inner nodes
// are union, intersection and difference. A ray is answered by merging the leaves' sorted
// span lists bottom-up; surfaces of subtracted solids come back with their normals turned.
#include <functional>
#include <memory>
#include <vector>

#include "geometry/lattice_source.h"
#include "geometry/shape.h"
#include "math/transform.h"

namespace lat {

enum class CsgOp { kUnion, kIntersection, kDifference };

// A leaf tag meaning "no material of its own": the object's material applies.
inline constexpr std::uint32_t kNoMaterial = 0xFFFFFFFFu;
// Surfaces one tree can number (LatticeSource::surface_count): a crossing's leaf field below its flip
// bit. Instances of CSG primitives as leaves multiply them.
inline constexpr std::uint32_t kMaxCsgSurfaces = Crossing::kFlipBit - 1;

struct CsgLeaf {
    std::shared_ptr<const Shape> shape;
    Transform xf;           // leaf coordinates -> the CSG object's coordinates
    std::uint32_t tag = 0;  // material of the leaf's surface
    int primitive = -1;     // for an instance of a scene primitive: its index
};

class CsgShape final : public Shape, public LatticeSource, public Pieces {
public:
    // Children are references returned by add_leaf / add_node. Nodes are n-ary: union and
    // intersection of all children; difference is the first child minus all the others.
    int add_leaf(CsgLeaf leaf);  // requires room_for(*leaf.shape)
    // Whether the tree can number the surfaces of one more leaf of this shape.
    bool room_for(const Shape& s) const {
        return ShapeSource(s).surface_count() <= kMaxCsgSurfaces - surfaces_;
    }
    int add_node(CsgOp op, std::vector<int> children);
    // Ends construction; the tree must be non-empty.
    void set_root(int ref);

    // The scene primitives that instance leaves refer to (with repeats).
    std::vector<int> leaf_primitives() const;
    // A copy whose instance leaves trace shape(primitive) instead (lattice mode); null when
    // no leaf is an instance.
    using PrimitiveShapeFn = std::function<std::shared_ptr<const Shape>(int primitive)>;
    std::shared_ptr<CsgShape> with_primitive_shapes(const PrimitiveShapeFn& shape) const;

    // The material of each surface the leaf field of its crossings numbers (kNoMaterial: the
    // object's): a leaf's tag, or, for a leaf that is itself a tree, its own surfaces'
    // materials where they have one. (A scene primitive's tree has none: its instances take
    // their object's material, and an instance leaf its leaf's tag, however it is traced.)
    std::span<const std::uint32_t> surface_materials() const { return materials_; }

    Bounds3 bounds() const override;
    // The tree's bounds from its leaves' own placed bounds: tighter than the box of the box.
    Bounds3 placed_bounds(const Transform& xf) const override {
        return lat::intersect(placed_bounds(root_, xf), xf.bounds(bounds()));
    }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override;
    bool cheap_normal(const Crossing& c) const override;
    std::uint32_t surface_count() const override { return surfaces_; }
    bool names_surface(const Crossing& c) const override;
    // A leaf's stored surface point (lattices) is carried to CSG coordinates.
    SurfacePoint surface(const Ray& r, const Crossing& c) const override;
    bool inside(Vec3 p) const override { return inside(root_, p); }
    // Pieces (exact lattices) are the leaves: a leaf whose solid keeps away from a ray is
    // empty along it, and the tree is evaluated with the others.
    std::size_t piece_count() const override { return leaves_.size(); }
    // The tree evaluates every leaf whose bounds the ray meets: their costs, summed.
    double intersect_cost() const override;
    void piece_spheres(std::size_t i, std::vector<BoundingSphere>& out) const override;
    void pieces_spans(std::span<const std::uint32_t> on, const Ray& r,
                      SpanList& out) const override;
    // The largest of the leaves' (lattices have one), in this shape's units.
    double surface_tolerance() const override { return tolerance_; }

private:
    // A crossing's leaf field numbers surfaces: one per leaf, except that a leaf whose shape
    // names several (a tree: an instance of a CSG primitive, exact or through a `candidates`
    // lattice) has a range, so that normals and materials are those of the surface crossed.
    struct Leaf {
        CsgLeaf leaf;
        ShapeSource source;           // leaf.shape's
        Bounds3 bounds;               // in CSG coordinates
        bool numbered;                // its shape names several surfaces
        std::uint32_t first_surface;  // its numbers: [first_surface, + its surface_count())
    };
    std::uint32_t surfaces_ = 0;
    std::vector<std::uint32_t> materials_;  // per surface number (surface_materials)
    // The leaf of crossing c, and c as that leaf reported it (its flip bit cleared: this
    // tree's flips count them all).
    struct Located {
        const Leaf* leaf;
        Crossing in_leaf;
    };
    Located locate(const Crossing& c) const;
    struct Node {
        CsgOp op;
        std::vector<int> children;
        Bounds3 bounds;
    };

    std::vector<Leaf> leaves_;
    std::vector<Node> nodes_;
    int root_ = 0;
    double tolerance_ = 0;

    Bounds3 compute_bounds(int ref);
    Bounds3 placed_bounds(int ref, const Transform& xf) const;
    // The spans of subtree ref along r's line; `on`, when set, lists the leaves evaluated
    // (ascending), the others counting as empty.
    using LeafSet = std::span<const std::uint32_t>;
    void eval(int ref, const Ray& r, SpanList& out, const LeafSet* on) const;
    bool inside(int ref, Vec3 p) const;
};

// out = a op b for sorted, disjoint span lists; boundaries that b contributes to a difference
// get their flip bit toggled. Zero-length results are dropped.
void combine_spans(const SpanList& a, const SpanList& b, CsgOp op, SpanList& out);

// The materials of a CSG tree's surfaces (CsgShape::surface_materials); empty for any other
// shape, whose crossings take the object's material.
std::span<const std::uint32_t> csg_surface_materials(const Shape& s);
// The scene primitives that a CSG tree's instance leaves refer to (with repeats); none for any
// other shape.
std::vector<int> csg_leaf_primitives(const Shape& s);
// A copy of a CSG tree whose instance leaves trace shape(primitive) instead (lattice mode);
// null for any other shape, or a tree without instance leaves.
std::shared_ptr<const Shape> csg_with_primitive_shapes(const Shape& s,
                                                       const CsgShape::PrimitiveShapeFn& shape);

}  // namespace lat
