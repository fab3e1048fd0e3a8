#include "csg/csg_shape.h"

#include "geometry/scratch_spans.h"

#include <cassert>
#include <algorithm>
#include <cmath>

namespace lat {
namespace {

constexpr bool is_leaf_ref(int ref) { return ref < 0; }
constexpr std::size_t leaf_of(int ref) { return static_cast<std::size_t>(-ref - 1); }

bool apply(CsgOp op, bool a, bool b) {
    switch (op) {
        case CsgOp::kUnion: return a || b;
        case CsgOp::kIntersection: return a && b;
        case CsgOp::kDifference: return a && !b;
    }
    return false;
}

}  // namespace

void combine_spans(const SpanList& a, const SpanList& b, CsgOp op, SpanList& out) {
    out.clear();
    std::size_t i = 0, j = 0;
    bool in_a = false, in_b = false, in_out = false;
    // Each list alternates in/out crossings; walk both in order of t.
    auto next_t = [](const SpanList& l, std::size_t k, bool inside) {
        if (k >= l.size()) return kInfinity;
        return inside ? l[k].out.t : l[k].in.t;
    };
    while (true) {
        const double ta = next_t(a, i, in_a), tb = next_t(b, j, in_b);
        const bool a_done = i >= a.size(), b_done = j >= b.size();
        if (a_done && b_done) break;
        Crossing c;
        bool from_b;
        if (!a_done && (b_done || ta <= tb)) {
            c = in_a ? a[i].out : a[i].in;
            if (in_a) ++i;
            in_a = !in_a;
            from_b = false;
        } else {
            c = in_b ? b[j].out : b[j].in;
            if (in_b) ++j;
            in_b = !in_b;
            from_b = true;
        }
        const bool now = apply(op, in_a, in_b);
        if (now == in_out) continue;
        if (from_b && op == CsgOp::kDifference) c.leaf ^= Crossing::kFlipBit;
        if (now) {
            out.push_back({c, {kInfinity, 0, 0}});
        } else if (c.t > out.back().in.t) {
            out.back().out = c;
        } else {
            out.pop_back();  // zero-length span from coincident crossings
        }
        in_out = now;
        if (!now && op != CsgOp::kUnion && (i >= a.size())) break;  // nothing more can start
    }
}

int CsgShape::add_leaf(CsgLeaf leaf) {
    const std::span<const std::uint32_t> inner = csg_surface_materials(*leaf.shape);
    const Bounds3 b = leaf.shape->placed_bounds(leaf.xf);
    const ShapeSource source(*leaf.shape);
    const std::uint32_t first = surfaces_, count = source.surface_count();
    assert(count >= 1 && room_for(*leaf.shape));
    surfaces_ += count;
    for (std::uint32_t k = 0; k < count; ++k)
        materials_.push_back(inner.size() == count && inner[k] != kNoMaterial ? inner[k] : leaf.tag);
    leaves_.push_back({std::move(leaf), source, b, count > 1, first});
    return -static_cast<int>(leaves_.size());
}

int CsgShape::add_node(CsgOp op, std::vector<int> children) {
    assert(!children.empty());
    nodes_.push_back({op, std::move(children), {}});
    return static_cast<int>(nodes_.size()) - 1;
}

void CsgShape::set_root(int ref) {
    root_ = ref;
    compute_bounds(root_);
    tolerance_ = 0;
    for (const Leaf& l : leaves_) {
        const double t = l.leaf.shape->span_tolerance();
        if (t == 0) continue;
        tolerance_ = std::max(tolerance_, t * l.leaf.xf.max_stretch());
    }
}

Bounds3 CsgShape::compute_bounds(int ref) {
    if (is_leaf_ref(ref)) return leaves_[leaf_of(ref)].bounds;
    Node& n = nodes_[static_cast<std::size_t>(ref)];
    Bounds3 b = compute_bounds(n.children[0]);
    for (std::size_t k = 1; k < n.children.size(); ++k) {
        const Bounds3 c = compute_bounds(n.children[k]);
        if (n.op == CsgOp::kUnion) b = merge(b, c);
        else if (n.op == CsgOp::kIntersection) b = lat::intersect(b, c);
    }
    n.bounds = b;
    return b;
}

Bounds3 CsgShape::placed_bounds(int ref, const Transform& xf) const {
    if (is_leaf_ref(ref)) {
        const CsgLeaf& leaf = leaves_[leaf_of(ref)].leaf;
        return leaf.shape->placed_bounds(xf * leaf.xf);
    }
    const Node& n = nodes_[static_cast<std::size_t>(ref)];
    Bounds3 b = placed_bounds(n.children[0], xf);
    for (std::size_t k = 1; k < n.children.size(); ++k) {
        if (n.op == CsgOp::kDifference) break;  // within the first child's
        const Bounds3 c = placed_bounds(n.children[k], xf);
        b = n.op == CsgOp::kUnion ? merge(b, c) : lat::intersect(b, c);
    }
    return b;
}

std::vector<int> CsgShape::leaf_primitives() const {
    std::vector<int> out;
    for (const Leaf& l : leaves_)
        if (l.leaf.primitive >= 0) out.push_back(l.leaf.primitive);
    return out;
}

std::shared_ptr<CsgShape> CsgShape::with_primitive_shapes(const PrimitiveShapeFn& shape) const {
    bool any = false;
    for (const Leaf& l : leaves_) any = any || l.leaf.primitive >= 0;
    if (!any) return nullptr;
    auto out = std::make_shared<CsgShape>();
    for (const Leaf& l : leaves_) {
        CsgLeaf leaf = l.leaf;
        if (leaf.primitive >= 0) leaf.shape = shape(leaf.primitive);
        out->add_leaf(std::move(leaf));
    }
    out->nodes_ = nodes_;
    out->set_root(root_);
    return out;
}

Bounds3 CsgShape::bounds() const {
    return is_leaf_ref(root_) ? leaves_[leaf_of(root_)].bounds
                              : nodes_[static_cast<std::size_t>(root_)].bounds;
}

void CsgShape::eval(int ref, const Ray& r, SpanList& out, const LeafSet* on) const {
    double t0 = -kInfinity, t1 = kInfinity;
    if (is_leaf_ref(ref)) {
        const std::size_t li = leaf_of(ref);
        const Leaf& leaf = leaves_[li];
        if (on && !std::binary_search(on->begin(), on->end(), static_cast<std::uint32_t>(li)))
            return;
        if (leaf.bounds.empty() || (leaf.bounds.finite() && !clip_ray(leaf.bounds, r, t0, t1)))
            return;
        const std::size_t first = out.size();
        const Ray local = leaf.leaf.xf.is_identity() ? r : leaf.leaf.xf.inverse_ray(r);
        leaf.leaf.shape->spans(local, out);
        // A numbered leaf's crossings keep their surface (shifted into this tree's numbers) and
        // flip; others are the leaf's one surface (a table's stored normals face outward).
        for (std::size_t k = first; k < out.size(); ++k)
            for (Crossing* c : {&out[k].in, &out[k].out})
                c->leaf = leaf.numbered ? (c->leaf & Crossing::kFlipBit) |
                                              (leaf.first_surface + c->leaf_index())
                                        : leaf.first_surface;
        return;
    }
    const Node& n = nodes_[static_cast<std::size_t>(ref)];
    if (n.bounds.empty() || !clip_ray(n.bounds, r, t0, t1)) return;
    eval(n.children[0], r, out, on);
    // Nothing left to intersect with or subtract from: the other children need no evaluating.
    const auto settled = [&] { return out.empty() && n.op != CsgOp::kUnion; };
    if (n.children.size() == 1 || settled()) return;
    ScratchSpans b, c;
    for (std::size_t k = 1; k < n.children.size() && !settled(); ++k) {
        b->clear();
        eval(n.children[k], r, *b, on);
        if (b->empty() && n.op != CsgOp::kIntersection) continue;
        combine_spans(out, *b, n.op, *c);
        out.swap(*c);
    }
}

double CsgShape::intersect_cost() const {
    double cost = 0;
    for (const Leaf& l : leaves_) cost += l.leaf.shape ? l.source.intersect_cost() : 1.0;
    return cost;
}

void CsgShape::spans(const Ray& r, SpanList& out) const {
    ScratchSpans tmp;
    eval(root_, r, *tmp, nullptr);
    out.insert(out.end(), tmp->begin(), tmp->end());
}

bool CsgShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    ScratchSpans tmp;
    eval(root_, r, *tmp, nullptr);
    return first_crossing(*tmp, tmin, tmax, hit);
}

void CsgShape::pieces_spans(std::span<const std::uint32_t> on, const Ray& r, SpanList& out) const {
    assert(std::is_sorted(on.begin(), on.end()));
    ScratchSpans tmp;
    eval(root_, r, *tmp, &on);
    out.insert(out.end(), tmp->begin(), tmp->end());
}

// A leaf's spheres, carried to CSG coordinates: centres mapped, radii grown by the largest
// stretch. A leaf without finite bounds (a half-space) gets an unbounded sphere at the origin.
void CsgShape::piece_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
    const Leaf& leaf = leaves_[i];
    if (!leaf.bounds.finite()) {
        out.push_back({{0, 0, 0}, kInfinity});
        return;
    }
    const ShapeParts& parts = leaf.source.parts();
    const Transform& xf = leaf.leaf.xf;
    const double stretch = xf.max_stretch();
    const std::size_t first = out.size();
    for (std::size_t j = 0; j < parts.part_count(); ++j) parts.part_spheres(j, out);
    for (std::size_t k = first; k < out.size(); ++k)
        out[k] = {xf.point(out[k].center), out[k].radius * stretch};
}

CsgShape::Located CsgShape::locate(const Crossing& c) const {
    const std::uint32_t s = c.leaf_index();
    assert(s < surfaces_);  // a crossing of this shape (names_surface)
    const auto later = [](std::uint32_t v, const Leaf& l) { return v < l.first_surface; };
    const Leaf& leaf = *(std::upper_bound(leaves_.begin(), leaves_.end(), s, later) - 1);
    Crossing in_leaf = c;
    in_leaf.leaf = s - leaf.first_surface;
    return {&leaf, in_leaf};
}

bool CsgShape::names_surface(const Crossing& c) const {
    if (c.leaf_index() >= surfaces_) return false;
    const Located at = locate(c);
    return at.leaf->source.names_surface(at.in_leaf);
}

Vec3 CsgShape::normal(const Ray& r, const Crossing& c) const {
    const Located at = locate(c);
    const CsgLeaf& leaf = at.leaf->leaf;
    const Ray local = leaf.xf.is_identity() ? r : leaf.xf.inverse_ray(r);
    Vec3 n = leaf.shape->normal(local, at.in_leaf);
    if (!leaf.xf.is_identity()) n = normalize(leaf.xf.normal(n));
    return c.flipped() ? -n : n;
}

bool CsgShape::cheap_normal(const Crossing& c) const {
    const Located at = locate(c);
    return at.leaf->source.cheap_normal(at.in_leaf);
}

SurfacePoint CsgShape::surface(const Ray& r, const Crossing& c) const {
    if (!c.has_stored) return {r.at(c.t), normal(r, c)};
    const Located at = locate(c);
    const Transform& xf = at.leaf->leaf.xf;
    SurfacePoint s =
        at.leaf->numbered ? at.leaf->leaf.shape->surface(xf.inverse_ray(r), at.in_leaf) : c.stored;
    if (!xf.is_identity()) s = {xf.point(s.p), normalize(xf.normal(s.n))};
    if (c.flipped()) s.n = -s.n;
    return s;
}

bool CsgShape::inside(int ref, Vec3 p) const {
    if (is_leaf_ref(ref)) {
        const CsgLeaf& leaf = leaves_[leaf_of(ref)].leaf;
        return leaf.shape->inside(leaf.xf.is_identity() ? p : leaf.xf.inverse_point(p));
    }
    const Node& n = nodes_[static_cast<std::size_t>(ref)];
    bool v = inside(n.children[0], p);
    for (std::size_t k = 1; k < n.children.size(); ++k) v = apply(n.op, v, inside(n.children[k], p));
    return v;
}

std::span<const std::uint32_t> csg_surface_materials(const Shape& s) {
    const auto* csg = dynamic_cast<const CsgShape*>(&s);
    return csg ? csg->surface_materials() : std::span<const std::uint32_t>{};
}

std::vector<int> csg_leaf_primitives(const Shape& s) {
    const auto* csg = dynamic_cast<const CsgShape*>(&s);
    return csg ? csg->leaf_primitives() : std::vector<int>{};
}

std::shared_ptr<const Shape> csg_with_primitive_shapes(const Shape& s,
                                                       const CsgShape::PrimitiveShapeFn& shape) {
    const auto* csg = dynamic_cast<const CsgShape*>(&s);
    return csg ? csg->with_primitive_shapes(shape) : nullptr;
}

}  // namespace lat
