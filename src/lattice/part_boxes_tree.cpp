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

// Twice part p's centre along axis a; 0 for a box without one, so that orders stay strict.
float PartBoxes::centre(std::uint32_t p, std::size_t a) const {
    const float c = f_[p].lo[a] + f_[p].hi[a];
    return std::isfinite(c) ? c : 0.0f;
}

// Splits order[first, last) in two, sorted along the axis and at the place that give the least
// surface area heuristic: the areas of the halves' boxes, each times its parts (sorted by
// centre, ties by index; a box without a centre sorts as if centred at 0; an unbounded box
// costs as if huge, and equal costs go to the cut nearer the middle). A tuft's segments lie
// across each other near its root, where median cuts of their centres made children whose
// boxes overlapped. Each half keeps at least a quarter of the parts (rounded down), so that the
// tree stays shallow whatever the boxes: under 40 levels for 2^32 parts (tree_near_parts).
std::size_t PartBoxes::halve(std::vector<std::uint32_t>& order, std::size_t first,
                             std::size_t last) const {
    const std::size_t n = last - first;
    const auto at = [&](std::size_t i) { return order.begin() + static_cast<std::ptrdiff_t>(i); };
    const auto by_centre = [&](std::size_t axis) {
        return [this, axis](std::uint32_t x, std::uint32_t y) {
            const float cx = centre(x, axis), cy = centre(y, axis);
            return cx < cy || (cx == cy && x < y);
        };
    };
    const auto area = [](const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
        const double x = double(hi[0]) - double(lo[0]), y = double(hi[1]) - double(lo[1]),
                     z = double(hi[2]) - double(lo[2]);
        return std::isfinite(x + y + z) ? x * y + y * z + z * x : 1e300;
    };
    const auto grow = [&](std::array<float, 3>& lo, std::array<float, 3>& hi, std::uint32_t p) {
        for (std::size_t a = 0; a < 3; ++a)
            lo[a] = std::min(lo[a], f_[p].lo[a]), hi[a] = std::max(hi[a], f_[p].hi[a]);
    };
    const auto off_middle = [&](std::size_t k) { return k > n / 2 ? k - n / 2 : n / 2 - k; };
    std::vector<double> right(n + 1);
    double best = INFINITY;
    std::size_t best_axis = 0, best_k = n / 2;
    for (std::size_t axis = 0; axis < 3; ++axis) {
        std::sort(at(first), at(last), by_centre(axis));
        std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
        for (std::size_t k = n; k-- > 0;) {
            grow(lo, hi, order[first + k]);
            right[k] = area(lo, hi) * double(n - k);
        }
        lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
        for (std::size_t k = 1; k < n; ++k) {
            grow(lo, hi, order[first + k - 1]);
            if (k < n / 4 || n - k < n / 4) continue;
            const double cost = area(lo, hi) * double(k) + right[k];
            if (cost < best || (cost == best && off_middle(k) < off_middle(best_k)))
                best = cost, best_axis = axis, best_k = k;
        }
    }
    if (best_axis != 2) std::sort(at(first), at(last), by_centre(best_axis));  // 2: as it is
    return first + best_k;
}

// The node over order[first, last): a leaf of its parts when they are four or fewer, else a
// node over its quarters (its halves halved). Children are made before their parent, so the
// root is the last node.
PartBoxes::Made PartBoxes::make_node(std::vector<std::uint32_t>& order, std::size_t first,
                                     std::size_t last) {
    Node node{};
    Made made{0, {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    const auto hold = [&](std::uint32_t child, const std::array<float, 3>& lo,
                          const std::array<float, 3>& hi) {
        const std::size_t lane = node.count++;
        node.child[lane] = child;
        for (std::size_t a = 0; a < 3; ++a) {
            node.box.lo[a][lane] = lo[a], node.box.hi[a][lane] = hi[a];
            made.lo[a] = std::min(made.lo[a], lo[a]), made.hi[a] = std::max(made.hi[a], hi[a]);
        }
    };
    node.leaf = last - first <= 4;
    if (node.leaf) {
        for (std::size_t i = first; i < last; ++i) {
            const Box4& b = f_[order[i]];
            hold(order[i], {b.lo[0], b.lo[1], b.lo[2]}, {b.hi[0], b.hi[1], b.hi[2]});
        }
    } else {
        const std::size_t mid = halve(order, first, last);
        const std::array<std::size_t, 5> cut{first, halve(order, first, mid), mid,
                                             halve(order, mid, last), last};
        for (std::size_t c = 0; c < 4; ++c) {
            if (cut[c] == cut[c + 1]) continue;
            const Made m = make_node(order, cut[c], cut[c + 1]);
            hold(m.node, m.lo, m.hi);
        }
    }
    nodes_.push_back(node);
    made.node = static_cast<std::uint32_t>(nodes_.size() - 1);
    return made;
}

// Top down, four children a node (halve, twice).
void PartBoxes::build_tree() {
    std::vector<std::uint32_t> order(f_.size());
    std::iota(order.begin(), order.end(), 0u);
    make_node(order, 0, order.size());
}

bool PartBoxes::Ray4::tame(const Grow& g) const {
    const float reach = boxes_.extent_ + g.f;
    for (std::size_t k = 0; k < 3; ++k)
        if (!((reach + std::abs(o_[k])) * std::abs(inv_[k]) < 1e37f)) return false;
    return true;
}

std::size_t PartBoxes::tree_near_parts(const Ray4& slabs, const Ray4::Range& range,
                                       const Ray4::Grow& g, std::span<std::uint32_t> out) const {
    // A child holds at most about 9/16 of its parent's parts (halve): under 40 levels for
    // 2^32 parts, with at most 3 lanes a level left on the stack.
    std::array<std::uint32_t, 160> stack;
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
    // In list order. A ray finds a part or two: an insertion sort, where std::sort's set-up
    // cost more.
    if (n > 16) {
        std::sort(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
        return n;
    }
    for (std::size_t i = 1; i < n; ++i)
        for (std::size_t j = i; j > 0 && out[j] < out[j - 1]; --j) std::swap(out[j], out[j - 1]);
    return n;
}

}  // namespace lat
