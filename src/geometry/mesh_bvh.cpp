#include "geometry/mesh_bvh.h"

#include <algorithm>

namespace lat {

namespace {
constexpr std::uint32_t kLeafSize = 4;
}

MeshBvh::MeshBvh(const std::vector<Vec3>& positions, const std::vector<Triangle>& triangles) {
    const auto n = static_cast<std::uint32_t>(triangles.size());
    std::vector<Bounds3> boxes(n);
    std::vector<Vec3> centres(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        Bounds3 b;
        for (const std::uint32_t k : triangles[i]) b = merge(b, positions[k]);
        boxes[i] = b;
        centres[i] = b.center();
    }
    order_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) order_[i] = i;
    nodes_.reserve(2 * (n / kLeafSize + 1));
    if (n > 0) build(boxes, centres, 0, n);
}

// Median split on the longest axis of the centres' box: O(n log n), deterministic, and good
// enough for the few queries that come here.
std::uint32_t MeshBvh::build(std::vector<Bounds3>& boxes, std::vector<Vec3>& centres,
                             std::uint32_t lo, std::uint32_t hi) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    Bounds3 box, cbox;
    for (std::uint32_t i = lo; i < hi; ++i) {
        box = merge(box, boxes[order_[i]]);
        cbox = merge(cbox, centres[order_[i]]);
    }
    nodes_[index].box = box;
    if (hi - lo <= kLeafSize) {
        nodes_[index].first = lo;
        nodes_[index].count = hi - lo;
        return index;
    }
    const Vec3 e = cbox.extent();
    const std::size_t axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const std::uint32_t mid = lo + (hi - lo) / 2;
    std::nth_element(order_.begin() + lo, order_.begin() + mid, order_.begin() + hi,
                     [&](std::uint32_t a, std::uint32_t b) {
                         const double ca = centres[a][axis], cb = centres[b][axis];
                         return ca < cb || (ca == cb && a < b);
                     });
    build(boxes, centres, lo, mid);
    const std::uint32_t right = build(boxes, centres, mid, hi);
    nodes_[index].first = right;
    return index;
}

void MeshBvh::traverse(const Ray& r, double tmin, const double* tmax,
                       const std::function<bool(std::uint32_t)>& visit) const {
    if (nodes_.empty()) return;
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    const Vec3 inv = reciprocals(r.d);  // clip_ray's, once for every node
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        double t0 = tmin, t1 = *tmax;
        const double pad = 1e-9 * (1 + max_component(max(abs(node.box.lo), abs(node.box.hi))));
        if (!clip_line(expand(node.box, pad), r.o, r.d, inv, t0, t1))
            continue;
        if (node.count > 0) {
            for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
                if (visit(order_[i])) return;
            continue;
        }
        const auto self = static_cast<std::uint32_t>(&node - nodes_.data());
        // Depth is at most log2(n / kLeafSize) + 1 < 64 for any mesh we accept.
        stack[top++] = node.first;
        stack[top++] = self + 1;
    }
}

}  // namespace lat
