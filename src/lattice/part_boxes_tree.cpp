// PartBoxes' tree: near_parts for primitives of many parts (a tuft of 200 to 10,000 segments)
// visits the boxes near the ray instead of testing every one.
//
// Same parts as the flat scan, bit for bit: a leaf tests its parts' boxes with the flat scan's
// float test, and an inner node's lane holds the float minimum and maximum of its child's
// boxes, which every box below it lies in. The float test is monotone in the box while its
// products cannot overflow (Ray4::tame): each slab parameter (b - o) / d rounds monotonically
// in b, so a larger box's entry is no later and its exit no earlier, and a node is met whenever
// a box below it is. Rays that are not tame take the flat scan.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numeric>

#include "lattice/part_boxes.h"

namespace lat {
namespace {

// The lane of a node's box that holds a child's box (lo, hi per axis).
template <class Quad>
void set_lane(Quad& q, std::size_t lane, const std::array<float, 3>& lo,
              const std::array<float, 3>& hi) {
    for (std::size_t a = 0; a < 3; ++a) q.lo[a][lane] = lo[a], q.hi[a][lane] = hi[a];
}

}  // namespace

// Top down, four children a node: the parts' centres are split at the median along their
// widest axis, and each half again along its own, until a group holds four parts or fewer
// (a leaf). Children are made before their parent, so the root is the last node.
void PartBoxes::build_tree() {
    std::vector<std::uint32_t> order(f_.size());
    std::iota(order.begin(), order.end(), 0u);
    // (Twice the centre; 0 for a box without one, so that the order stays a strict one.)
    const auto centre = [&](std::uint32_t p, std::size_t a) {
        const float c = f_[p].lo[a] + f_[p].hi[a];
        return std::isfinite(c) ? c : 0.0f;
    };
    // Splits order[first, last) at its median along its centres' widest axis.
    const auto halve = [&](std::size_t first, std::size_t last) {
        std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
        for (std::size_t i = first; i < last; ++i)
            for (std::size_t a = 0; a < 3; ++a)
                lo[a] = std::min(lo[a], centre(order[i], a)),
                hi[a] = std::max(hi[a], centre(order[i], a));
        std::size_t axis = 0;
        for (std::size_t a = 1; a < 3; ++a)
            if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
        const std::size_t mid = first + (last - first) / 2;
        std::nth_element(order.begin() + static_cast<std::ptrdiff_t>(first),
                         order.begin() + static_cast<std::ptrdiff_t>(mid),
                         order.begin() + static_cast<std::ptrdiff_t>(last),
                         [&](std::uint32_t x, std::uint32_t y) {
                             return centre(x, axis) < centre(y, axis) ||
                                    (centre(x, axis) == centre(y, axis) && x < y);
                         });
        return mid;
    };
    struct Made {
        std::uint32_t node;
        std::array<float, 3> lo, hi;  // the box of all it holds
    };
    const auto make = [&](auto&& self, std::size_t first, std::size_t last) -> Made {
        Node node{};
        std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
        const auto hold = [&](std::size_t lane, std::uint32_t child, const std::array<float, 3>& l,
                              const std::array<float, 3>& h) {
            node.child[lane] = child;
            set_lane(node.box, lane, l, h);
            for (std::size_t a = 0; a < 3; ++a)
                lo[a] = std::min(lo[a], l[a]), hi[a] = std::max(hi[a], h[a]);
        };
        if (last - first <= 4) {
            node.leaf = true;
            node.count = static_cast<std::uint32_t>(last - first);
            for (std::size_t i = first; i < last; ++i) {
                const Box4& b = f_[order[i]];
                hold(i - first, order[i], {b.lo[0], b.lo[1], b.lo[2]}, {b.hi[0], b.hi[1], b.hi[2]});
            }
        } else {
            const std::size_t mid = halve(first, last);
            const std::array<std::size_t, 5> cut{first, halve(first, mid), mid, halve(mid, last),
                                                 last};
            node.count = 0;
            for (std::size_t c = 0; c < 4; ++c) {
                if (cut[c] == cut[c + 1]) continue;
                const Made m = self(self, cut[c], cut[c + 1]);
                hold(node.count++, m.node, m.lo, m.hi);
            }
        }
        nodes_.push_back(node);
        return {static_cast<std::uint32_t>(nodes_.size() - 1), lo, hi};
    };
    make(make, 0, order.size());
}

bool PartBoxes::Ray4::tame(const Grow& g) const {
    const float reach = boxes_.extent_ + g.f;
    for (std::size_t k = 0; k < 3; ++k)
        if (!((reach + std::abs(o_[k])) * std::abs(inv_[k]) < 1e37f)) return false;
    return true;
}

std::size_t PartBoxes::tree_near_parts(const Ray4& slabs, const Ray4::Range& range,
                                       const Ray4::Grow& g, std::span<std::uint32_t> out) const {
    // Each child holds about a quarter of its parent's parts (median splits): some 16 levels
    // for 2^32 parts, with at most 3 lanes a level left on the stack.
    std::array<std::uint32_t, 128> stack;
    std::size_t top = 0, n = 0;
    stack[top++] = static_cast<std::uint32_t>(nodes_.size() - 1);
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        unsigned m = slabs.meets_grown_node(node, range, g) & ((1u << node.count) - 1);
        for (; m != 0; m &= m - 1) {
            const std::uint32_t child = node.child[std::countr_zero(m)];
            if (node.leaf)
                out[n++] = child;
            else
                stack[top++] = child;
        }
        assert(top + 4 <= stack.size());
    }
    std::sort(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
}

}  // namespace lat
