// CSG: span-list merging by hand, and trees of real shapes against point-membership sampling.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "csg/csg_shape.h"
#include "geometry/halfspace.h"
#include "geometry/lattice_source.h"
#include "geometry/named_shapes.h"
#include "geometry/sphere.h"

namespace lat {
namespace {

Span span(double a, double b, std::uint32_t leaf) { return {{a, 0, leaf}, {b, 0, leaf}}; }

TEST(CsgMerge, UnionIntersectionDifference) {
    const SpanList a{span(0, 2, 0), span(5, 7, 0)};
    const SpanList b{span(1, 3, 1), span(6, 6.5, 1)};
    SpanList out;
    combine_spans(a, b, CsgOp::kUnion, out);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].in.t, 0);
    EXPECT_EQ(out[0].out.t, 3);
    EXPECT_EQ(out[0].out.leaf, 1u);
    EXPECT_EQ(out[1].in.t, 5);
    EXPECT_EQ(out[1].out.t, 7);

    combine_spans(a, b, CsgOp::kIntersection, out);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].in.t, 1);
    EXPECT_EQ(out[0].out.t, 2);
    EXPECT_EQ(out[1].in.t, 6);
    EXPECT_EQ(out[1].out.t, 6.5);

    combine_spans(a, b, CsgOp::kDifference, out);
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(out[0].in.t, 0);
    EXPECT_EQ(out[0].out.t, 1);
    // The surface of the subtracted solid comes back flipped.
    EXPECT_TRUE(out[0].out.flipped());
    EXPECT_EQ(out[0].out.leaf_index(), 1u);
    EXPECT_EQ(out[1].in.t, 5);
    EXPECT_EQ(out[1].out.t, 6);
    EXPECT_EQ(out[2].in.t, 6.5);
    EXPECT_TRUE(out[2].in.flipped());
    EXPECT_EQ(out[2].out.t, 7);
    EXPECT_FALSE(out[2].out.flipped());
}

TEST(CsgMerge, InfiniteAndCoincidentSpans) {
    const SpanList half{span(-kInfinity, 4, 0)};
    const SpanList ball{span(2, 6, 1)};
    SpanList out;
    combine_spans(half, ball, CsgOp::kIntersection, out);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].in.t, 2);
    EXPECT_EQ(out[0].out.t, 4);
    combine_spans(half, ball, CsgOp::kDifference, out);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].in.t, -kInfinity);
    EXPECT_EQ(out[0].out.t, 2);
    // Touching spans subtract to nothing, not to a zero-length sliver.
    const SpanList same{span(2, 4, 1)};
    combine_spans(SpanList{span(2, 4, 0)}, same, CsgOp::kDifference, out);
    EXPECT_TRUE(out.empty());
}

// Builds (sphere A - sphere B) intersected with a half-space, nested two levels deep.
std::shared_ptr<CsgShape> sample_tree() {
    auto csg = std::make_shared<CsgShape>();
    const int a = csg->add_leaf({std::make_shared<SphereShape>(Vec3{0, 0, 0}, 1.0), {}, 1});
    const int b = csg->add_leaf({std::make_shared<SphereShape>(Vec3{0.8, 0, 0}, 0.6), {}, 2});
    const int h = csg->add_leaf({std::make_shared<HalfSpaceShape>(Vec3{0, 0, 0.5}, Vec3{0, 0, 1}),
                                 {}, 3});
    const int torus_leaf = [&] {
        PlacedShape t = make_torus({0, 0, -0.2}, {1, 0, 0}, 0.7, 0.15);
        return csg->add_leaf({t.shape, t.placement, 4});
    }();
    const int diff = csg->add_node(CsgOp::kDifference, {a, b});
    const int cut = csg->add_node(CsgOp::kIntersection, {diff, h});
    csg->set_root(csg->add_node(CsgOp::kUnion, {cut, torus_leaf}));
    return csg;
}

// Walks random lines: membership of the solid must agree with its spans away from their ends.
void expect_spans_match_membership(const Shape& csg) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-2, 2);
    int checked = 0;
    for (int n = 0; n < 3000; ++n) {
        const Ray r{{u(rng), u(rng), u(rng)}, normalize(Vec3{u(rng), u(rng), u(rng)})};
        SpanList spans;
        csg.spans(r, spans);
        for (double t = -6; t <= 6; t += 0.01) {
            bool in_span = false, near_end = false;
            for (const Span& s : spans) {
                in_span = in_span || (t > s.in.t && t < s.out.t);
                near_end = near_end || std::abs(t - s.in.t) < 1e-7 || std::abs(t - s.out.t) < 1e-7;
            }
            if (near_end) continue;
            ASSERT_EQ(in_span, csg.inside(r.at(t))) << "ray " << n << " t " << t;
            ++checked;
        }
    }
    EXPECT_GT(checked, 100000);
}

TEST(CsgTree, SpansAgreeWithMembershipSampling) { expect_spans_match_membership(*sample_tree()); }

// A tree whose leaves are trees (an instance of a CSG primitive in a CSG object): each level's
// scratch lists must stay its own.
TEST(CsgTree, TreesAsLeavesKeepTheirOwnLists) {
    auto outer = std::make_shared<CsgShape>();
    const int inner = outer->add_leaf({sample_tree(), Transform::translate({0.3, 0, 0}), 1});
    const int again = outer->add_leaf({sample_tree(), Transform::rotate({0, 0, 1}, 1.0), 2});
    const int ball = outer->add_leaf({std::make_shared<SphereShape>(Vec3{0, 0.5, 0}, 0.7), {}, 3});
    const int cut = outer->add_node(CsgOp::kDifference, {inner, ball});
    outer->set_root(outer->add_node(CsgOp::kUnion, {cut, again}));
    expect_spans_match_membership(*outer);
}

// Pieces (exact lattices) are the leaves: switching off the leaves whose solids keep away from
// a line changes none of its spans; all leaves on is the tree itself.
TEST(CsgTree, LeavesAwayFromALineCanBeSwitchedOff) {
    const auto csg = sample_tree();
    ASSERT_EQ(csg->piece_count(), 4u);
    EXPECT_FALSE(ShapeSource(*csg).pieces_are_union());
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-2, 2);
    int switched_off = 0;
    for (int n = 0; n < 5000; ++n) {
        const Ray r{{u(rng), u(rng), u(rng)}, normalize(Vec3{u(rng), u(rng), u(rng)})};
        std::vector<std::uint32_t> on;
        const std::vector<std::uint32_t> all{0, 1, 2, 3};
        for (std::uint32_t i = 0; i < 4; ++i) {
            std::vector<BoundingSphere> spheres;
            csg->piece_spheres(i, spheres);
            bool near = false;
            for (const BoundingSphere& b : spheres) {
                const Vec3 w = b.center - r.o;
                near = near || length(w - r.d * dot(w, r.d)) <= b.radius;  // or infinite
            }
            if (near) on.push_back(i);
        }
        switched_off += static_cast<int>(4 - on.size());
        SpanList whole, all_on, some_on;
        csg->spans(r, whole);
        csg->pieces_spans(all, r, all_on);
        csg->pieces_spans(on, r, some_on);
        for (const SpanList* l : {&all_on, &some_on}) {
            ASSERT_EQ(l->size(), whole.size()) << n;
            for (std::size_t k = 0; k < whole.size(); ++k) {
                ASSERT_EQ((*l)[k].in.t, whole[k].in.t) << n;
                ASSERT_EQ((*l)[k].in.leaf, whole[k].in.leaf) << n;
                ASSERT_EQ((*l)[k].out.t, whole[k].out.t) << n;
            }
        }
    }
    EXPECT_GT(switched_off, 4000);
    // The half-space (leaf 2) is unbounded: near every line.
    std::vector<BoundingSphere> h;
    csg->piece_spheres(2, h);
    ASSERT_EQ(h.size(), 1u);
    EXPECT_EQ(h[0].radius, kInfinity);
}

TEST(CsgTree, SubtractedSurfaceNormalPointsOutOfTheResult) {
    const auto csg = sample_tree();
    // Along +x at y = z = 0: enter the big sphere at x = -1, leave the solid where the small
    // sphere starts (x = 0.2); the normal there must point along +x (out of A - B).
    const Ray r{{-3, 0, 0}, {1, 0, 0}};
    Crossing c;
    ASSERT_TRUE(csg->intersect(r, 2.5, kInfinity, c));
    EXPECT_NEAR(c.t, 3.2, 1e-12);
    EXPECT_TRUE(c.flipped());
    EXPECT_EQ(csg->surface_materials()[c.leaf_index()], 2u);
    EXPECT_NEAR(length(csg->normal(r, c) - Vec3{1, 0, 0}), 0, 1e-12);
}

// The materials of a tree's surfaces: its leaves' tags, and for a leaf that is itself a tree
// (an instance of a CSG primitive), the inner tree's own where they have one, else the leaf's.
TEST(CsgTree, NestedTreesNumberTheirSurfacesMaterials) {
    auto inner = std::make_shared<CsgShape>();
    const int own = inner->add_leaf({std::make_shared<SphereShape>(Vec3{0, 0, 0}, 1.0), {}, 7});
    const int none = inner->add_leaf(
        {std::make_shared<SphereShape>(Vec3{0.5, 0, 0}, 0.7), {}, kNoMaterial});
    inner->set_root(inner->add_node(CsgOp::kUnion, {own, none}));
    auto outer = std::make_shared<CsgShape>();
    const int ball = outer->add_leaf({std::make_shared<SphereShape>(Vec3{3, 0, 0}, 0.5), {}, 1});
    const int tree = outer->add_leaf({inner, {}, 2, 0});
    outer->set_root(outer->add_node(CsgOp::kUnion, {ball, tree}));
    const std::vector<std::uint32_t> want{1, 7, 2};
    const auto got = outer->surface_materials();
    EXPECT_EQ(std::vector<std::uint32_t>(got.begin(), got.end()), want);
    EXPECT_TRUE(csg_surface_materials(SphereShape({0, 0, 0}, 1)).empty());

    // A ray through the inner tree's second sphere alone names the surface of material 2 (the
    // leaf's: that sphere has none).
    Crossing c;
    ASSERT_TRUE(outer->intersect({{0.9, 0, -5}, {0, 0, 1}}, 0, kInfinity, c));
    EXPECT_EQ(outer->surface_materials()[c.leaf_index()], 2u);

    // An instance leaf swapped for another shape (its lattice, in lattice mode) takes the
    // leaf's tag for every surface that shape numbers: a scene primitive's tree carries no
    // materials of its own.
    class NumbersTwo final : public Shape, public LatticeSource {
    public:
        Bounds3 bounds() const override { return {{-1, -1, -1}, {1, 1, 1}}; }
        bool intersect(const Ray&, double, double, Crossing&) const override { return false; }
        void spans(const Ray&, SpanList&) const override {}
        Vec3 normal(const Ray&, const Crossing&) const override { return {0, 0, 1}; }
        bool inside(Vec3) const override { return false; }
        bool names_surface(const Crossing& c) const override { return c.leaf < 2; }
        std::uint32_t surface_count() const override { return 2; }
        double intersect_cost() const override { return 1; }
    };
    const auto two =
        csg_with_primitive_shapes(*outer, [&](int) { return std::make_shared<NumbersTwo>(); });
    ASSERT_TRUE(two);
    const auto swapped = csg_surface_materials(*two);
    EXPECT_EQ(std::vector<std::uint32_t>(swapped.begin(), swapped.end()),
              (std::vector<std::uint32_t>{1, 2, 2}));
    const auto one = csg_with_primitive_shapes(
        *outer, [&](int) { return std::make_shared<SphereShape>(Vec3{0, 0, 0}, 1.0); });
    const auto tagged = csg_surface_materials(*one);
    EXPECT_EQ(std::vector<std::uint32_t>(tagged.begin(), tagged.end()),
              (std::vector<std::uint32_t>{1, 2}));
}

TEST(CsgTree, BoundsFollowTheOperators) {
    const auto csg = sample_tree();
    const Bounds3 b = csg->bounds();
    EXPECT_TRUE(b.finite());
    EXPECT_NEAR(b.hi.z, 0.65, 1e-9);  // the torus reaches higher than the half-space cut
    EXPECT_NEAR(b.lo.x, -1.0, 1e-9);
}

}  // namespace
}  // namespace lat
