#pragma once
// The boxes of a primitive's parts, for rejecting candidates cheaply: a candidate whose box the
// real ray misses, or meets only outside the parameter range asked, cannot give a crossing
// there, and costs a slab test instead of an exact intersection (candidate lists hold every part
// within 0.71 cells of the snapped segment; the ray meets few of them).
//
// The test runs in float, four lanes at once (x, y, z and a neutral lane). Error bound: every
// box is padded by kPad x D (D: the lattice box's diagonal plus its largest coordinate) before
// being rounded outward to float, and the ray's origin is first moved (in double) to the point
// of its line nearest the lattice box's centre, so that every coordinate and every distance
// along the ray inside the box stays below 2D. Float rounding of the origin, of (lo - o) and of
// 1/d then moves a slab plane by under 8 x 2^-24 x 2D < 1e-6 D, far inside the padding: the
// float interval always contains the exact one of the unpadded box, so no part that could
// answer is ever rejected (images stay identical to exact mode). Rays with a direction
// component too small for a float reciprocal take the same test in double.
#include <immintrin.h>

#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/parts.h"

namespace lat {

class PartBoxes {
    struct Node;  // of the tree (below)

public:
    // box: the lattice box (primitive units) that every part and every crossing lies in. tree:
    // build the tree near_parts searches (more than kTreeFrom parts; `candidates` never asks).
    PartBoxes(const ShapeParts& primitive, const Bounds3& box, bool tree = false);

    // The first crossing in (tmin, tmax) of the union of the listed parts of primitive (the
    // one the boxes were made for): each part whose box the ray meets within the range left
    // is intersected, in list order (ties go to the earlier part, as in a loop over them all);
    // lists of at most kFewParts skip the boxes.
    bool first_crossing(const ShapeParts& primitive, std::span<const std::uint32_t> parts, const Ray& r,
                        double tmin, double tmax, Crossing& hit) const;
    // Whether any listed part of primitive blocks r within (tmin, tmax).
    bool any_occludes(const ShapeParts& primitive, std::span<const std::uint32_t> parts, const Ray& r,
                      double tmin, double tmax) const;
    // Lists up to this long are intersected without their boxes: for so few parts, preparing
    // the four-lane test costs more than the exact tests it saves (Plate 4 in `candidates`, hair
    // lists of about 3 parts: 76 -> 72 ms; Plate 5 100 -> 91; the tufts' longer lists unchanged).
    static constexpr std::size_t kFewParts = 8;
    // The parts, in order, whose box grown by `grow` on every side the ray's line meets after
    // tmin: all that a ray parallel to r within grow of its line can meet there (same t). out
    // holds at least the part count; returns how many were written. Primitives of more than
    // kTreeFrom parts, made with the tree, are searched through it (the same parts); rays with
    // a direction component too small for the float test scan every part in double.
    std::size_t near_parts(const Ray& r, double grow, double tmin,
                           std::span<std::uint32_t> out) const;
    // Primitives of more than this many parts get the tree: a tuft of 200 parts spent half its
    // render testing every box (sub-rays of 455 ms, tables of 608, exact at 4 spp 287).
    static constexpr std::size_t kTreeFrom = 32;

    // One ray (primitive units), prepared once a visit for any number of tests.
    class Ray4 {
    public:
        Ray4(const PartBoxes& boxes, const Ray& r);
        // A parameter range [tmin, tmax] of the ray, prepared for meets().
        struct Range {
            double tmin, tmax;
            float lo, hi;  // shifted and widened for the float test
        };
        Range range(double tmin, double tmax) const;
        // Whether the tests run in float (else in double: a direction component too small).
        bool in_float() const { return use_float_; }
        // Whether the ray's line meets part i's box at some t in the range.
        bool meets(std::uint32_t i, const Range& r) const {
            return use_float_ ? meets_float(boxes_.f_[i], r) : meets_double(boxes_.exact_[i], r);
        }
        // The same for the listed parts parts[0] to parts[n - 1] (n from 1 to 4) at once: bit
        // j for parts[j]. Candidate lists run to a hundred parts (a tuft of 10,000 segments),
        // of which a ray meets about one.
        unsigned meets_listed(const std::uint32_t* parts, std::size_t n, const Range& r) const;
        // Calls f(part) for each listed part whose box the ray meets within r, in list order,
        // until f returns true; returns whether it did. r is read before each four parts, so f
        // may narrow it (the parts of a four already met are handed over all the same).
        template <class F>
        bool any_listed(std::span<const std::uint32_t> parts, const Range& r, F&& f) const {
            for (std::size_t k = 0; k < parts.size(); k += 4) {
                const std::size_t n = parts.size() - k < 4 ? parts.size() - k : 4;
                for (unsigned m = meets_listed(&parts[k], n, r); m != 0; m &= m - 1)
                    if (f(parts[k + static_cast<std::size_t>(std::countr_zero(m))])) return true;
            }
            return false;
        }
        // A growth of every box by g on every side, prepared once for meets_grown.
        struct Grow {
            double g;
            float f;  // g for the float test, rounded up with a margin
        };
        static Grow grow(double g);
        // Whether the ray's line meets part i's box grown by g at some t in the range.
        bool meets_grown(std::uint32_t i, const Range& r, const Grow& g) const;
        // The same for parts 4 k to 4 k + 3 at once (bit j: part 4 k + j), the float test
        // lane for lane; float rays only.
        unsigned meets_grown4(std::size_t k, const Range& r, const Grow& g) const {
            return meets_grown_quad(boxes_.quads_[k], r, g);
        }
        // The lanes of a tree node's box (its children's boxes) grown by g that the ray meets.
        unsigned meets_grown_node(const Node& n, const Range& r, const Grow& g) const {
            return meets_grown_quad(n.box, r, g);
        }
        // Whether the float test cannot overflow for boxes within the tree's (growth g): then
        // a box's test answers yes whenever one of a box it holds does (tree_near_parts).
        bool tame(const Grow& g) const;

    private:
        const PartBoxes& boxes_;
        const Ray& ray_;
        bool use_float_ = true;
        double shift_ = 0;  // the float test's t is the ray's t minus this
        alignas(16) float o_[4], inv_[4];
        __m128 ob_[3], invb_[3];  // o_[a] and inv_[a] in every lane
        bool meets_double(const Bounds3& b, const Range& r) const;
        // Four boxes at once, given axis by axis (lane j: box j): bit j, whether the ray meets
        // box j within r. Lane j is meets_float's test of box j, operation for operation: the
        // slabs' entries and exits combined in its order (max(max(x, y), max(z, -inf)), which
        // matters for a NaN). Inline, with the ray broadcast once (ob_, invb_): a tuft's tree
        // tests about ten nodes a ray, and the call and the broadcasts were a third of each.
        unsigned meets4(const __m128 lo[3], const __m128 hi[3], const Range& r) const {
            __m128 entry[3], exit[3];
            for (std::size_t a = 0; a < 3; ++a) {
                const __m128 t0 = _mm_mul_ps(_mm_sub_ps(lo[a], ob_[a]), invb_[a]);
                const __m128 t1 = _mm_mul_ps(_mm_sub_ps(hi[a], ob_[a]), invb_[a]);
                entry[a] = _mm_min_ps(t0, t1);
                exit[a] = _mm_max_ps(t0, t1);
            }
            const __m128 tn = _mm_max_ps(_mm_max_ps(entry[0], entry[1]),
                                         _mm_max_ps(entry[2], _mm_set1_ps(-INFINITY)));
            const __m128 tf = _mm_min_ps(_mm_min_ps(exit[0], exit[1]),
                                         _mm_min_ps(exit[2], _mm_set1_ps(INFINITY)));
            const __m128 lo_t = _mm_max_ps(tn, _mm_set1_ps(r.lo));
            const __m128 hi_t = _mm_min_ps(tf, _mm_set1_ps(r.hi));
            return static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(lo_t, hi_t)));
        }
        template <class Q>
        unsigned meets_grown_quad(const Q& b, const Range& r, const Grow& g) const {
            assert(use_float_);
            const __m128 gf = _mm_set1_ps(g.f);
            __m128 lo[3], hi[3];
            for (std::size_t a = 0; a < 3; ++a) {
                lo[a] = _mm_sub_ps(_mm_load_ps(b.lo[a]), gf);
                hi[a] = _mm_add_ps(_mm_load_ps(b.hi[a]), gf);
            }
            return meets4(lo, hi, r);
        }
        template <class B>
        bool meets_float(const B& b, const Range& r) const {
            const __m128 o = _mm_load_ps(o_), inv = _mm_load_ps(inv_);
            const __m128 t0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(b.lo), o), inv);
            const __m128 t1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(b.hi), o), inv);
            // Lanes 0-2: the slabs' entries and exits; lane 3 is neutral. Largest entry, least
            // exit.
            __m128 tn = _mm_min_ps(t0, t1), tf = _mm_max_ps(t0, t1);
            tn = _mm_max_ps(tn, _mm_shuffle_ps(tn, tn, _MM_SHUFFLE(2, 3, 0, 1)));
            tn = _mm_max_ps(tn, _mm_shuffle_ps(tn, tn, _MM_SHUFFLE(1, 0, 3, 2)));
            tf = _mm_min_ps(tf, _mm_shuffle_ps(tf, tf, _MM_SHUFFLE(2, 3, 0, 1)));
            tf = _mm_min_ps(tf, _mm_shuffle_ps(tf, tf, _MM_SHUFFLE(1, 0, 3, 2)));
            const float lo = _mm_cvtss_f32(tn), hi = _mm_cvtss_f32(tf);
            return (lo > r.lo ? lo : r.lo) <= (hi < r.hi ? hi : r.hi);
        }
    };

private:
    struct alignas(16) Box4 {
        float lo[4], hi[4];
    };
    std::vector<Bounds3> exact_;  // the parts' bounds padded as in double
    std::vector<Box4> f_;         // padded by kPad x D, rounded outward
    // f_ by fours, axis by axis (part 4 k + j in lane j of quads_[k]; lanes past the last part
    // are never reported).
    struct alignas(16) BoxQuad {
        float lo[3][4], hi[3][4];
    };
    std::vector<BoxQuad> quads_;
    // The tree (more than kTreeFrom parts): nodes of up to four children each, a child's box
    // in a lane of the node's; a leaf's children are parts, an inner node's are nodes.
    // nodes_.back() is the root. A box holds its children's (float min and max: exact).
    struct alignas(16) Node {
        BoxQuad box;
        std::uint32_t child[4];
        std::uint32_t count;  // children, 1 to 4
        bool leaf;
    };
    std::vector<Node> nodes_;
    float extent_ = 0;  // the largest coordinate of any box (relative to center_)
    Vec3 center_;

    struct Made {
        std::uint32_t node;
        std::array<float, 3> lo, hi;  // the box of all it holds
    };
    void build_tree();
    float centre(std::uint32_t p, std::size_t a) const;
    std::size_t halve(std::vector<std::uint32_t>& order, std::size_t first, std::size_t last) const;
    Made make_node(std::vector<std::uint32_t>& order, std::size_t first, std::size_t last);
    std::size_t tree_near_parts(const Ray4& slabs, const Ray4::Range& range, const Ray4::Grow& g,
                                std::span<std::uint32_t> out) const;
};

}  // namespace lat
