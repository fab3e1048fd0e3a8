#pragma once
// Fitting the learned encoding's distance field (learned_field.h) to oriented surface points:
// each node near the surface takes the signed distance to the tangent plane of its nearest
// point, and that point's normal; the sign elsewhere spreads from those nodes.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/shape.h"
#include "lattice/encodings/learned/learned_field.h"

namespace lat {

// The fitted field, before its nodes are quantised.
struct FieldFit {
    FieldShape shape;  // g, nodes and dmax set; the widths are chosen later
    std::vector<std::uint64_t> dense_bits, sign_bits;
    std::uint64_t dense = 0;
    std::vector<double> dist;  // per node of each dense brick, in brick order
    std::vector<Vec3> normal;

    // The dense bricks' nodes at the widths of `s`.
    std::vector<std::uint64_t> quantise(const FieldShape& s) const;
};

// Node spacing g in lattice units; false when the grid would be unreasonably large. Parallel
// and deterministic.
bool fit_field(std::span<const SurfacePoint> points, std::array<int, 3> cells, double g,
               FieldFit& out);

}  // namespace lat
