#pragma once
// A bounding volume hierarchy over a triangle mesh, in double precision, for the queries the
// accelerator does not answer: whole-line spans (CSG), inside tests and the mesh's own
// intersect() when it is one leaf of something else. (Camera and shadow rays go through
// Embree, which holds the triangles one by one.)
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "math/bounds.h"
#include "math/ray.h"

namespace lat {

class MeshBvh {
public:
    using Triangle = std::array<std::uint32_t, 3>;
    MeshBvh() = default;
    MeshBvh(const std::vector<Vec3>& positions, const std::vector<Triangle>& triangles);

    // Calls visit(triangle) for every triangle whose box the ray meets within [tmin, *tmax];
    // visit may lower *tmax (closest-hit search) or return true to stop (any-hit search).
    void traverse(const Ray& r, double tmin, const double* tmax,
                  const std::function<bool(std::uint32_t)>& visit) const;

private:
    struct Node {
        Bounds3 box;
        std::uint32_t first = 0;  // leaf: first index into order_; inner: the right child
        std::uint32_t count = 0;  // triangles in a leaf; 0 for an inner node (left is next)
    };
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> order_;  // triangle indices, leaves' ranges

    std::uint32_t build(std::vector<Bounds3>& boxes, std::vector<Vec3>& centres,
                        std::uint32_t lo, std::uint32_t hi);
};

}  // namespace lat
