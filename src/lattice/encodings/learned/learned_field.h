#pragma once
// The learned encoding's model: a signed distance field of the primitive, fitted to the
// rasterized hits, on a grid of nodes g lattice units apart. Nodes are stored only in bricks of
// 4 x 4 x 4 voxels that the surface may pass through, (4 + 1)^3 nodes each: a quantised
// distance (clamped to +-dmax) and an octahedral unit normal; every other brick is all inside or
// all outside (one sign bit). A pair (a, b) is answered by marching the segment p_a -> p_b
// through the bricks and voxels to the first zero of the trilinear distance, with the normal
// interpolated trilinearly from the nodes' normals there.
#include <array>
#include <cstdint>
#include <vector>

#include "lattice/table.h"
#include "math/vec.h"

namespace lat {

inline constexpr int kBrick = 4;  // voxels per brick edge
inline constexpr int kBrickNodes = (kBrick + 1) * (kBrick + 1) * (kBrick + 1);  // 125

struct FieldShape {
    double g = 1;                // node spacing, lattice units
    std::array<int, 3> nodes{};  // per axis, >= 2
    double dmax = 1;             // distance codes span [-dmax, dmax], lattice units
    unsigned dist_bits = 8, normal_bits = 8;

    std::array<int, 3> bricks() const {
        return {(nodes[0] - 2) / kBrick + 1, (nodes[1] - 2) / kBrick + 1,
                (nodes[2] - 2) / kBrick + 1};
    }
    std::uint64_t brick_count() const {
        const auto b = bricks();
        return std::uint64_t(b[0]) * std::uint64_t(b[1]) * std::uint64_t(b[2]);
    }
    std::uint64_t node_bits() const { return dist_bits + 2 * normal_bits; }
    std::uint64_t brick_bits() const { return kBrickNodes * node_bits(); }
    // A node's codes: distance, then the normal's u and v.
    std::uint64_t encode_node(double d, Vec3 n) const;
};

// A segment in node coordinates, o + d t for t in [0, 1], with 1 / d per axis (0 where d is).
struct FieldSegment {
    Vec3 o, d, inv;
};

// The field over its words (in a payload, or in memory during the build): the dense-brick
// bitmap, the sign bitmap (1: inside) and the dense bricks' nodes in brick order.
class FieldView {
public:
    FieldView() = default;
    // Throws std::runtime_error when the bitmap does not hold `dense` bricks.
    FieldView(const FieldShape& s, const std::uint64_t* dense_bits, const std::uint64_t* sign_bits,
              const std::uint64_t* nodes, std::uint64_t dense);

    // The answer for the segment pa -> pb (lattice units): its first zero of the field.
    bool predict(Vec3 pa, Vec3 pb, TableHit& out) const;
    const FieldShape& shape() const { return s_; }
    // Bytes of the indexes built at open (not part of the payload).
    std::uint64_t index_bytes() const {
        return rank_.size() * sizeof(std::uint32_t) + voxels_.size() * sizeof(std::uint64_t) +
               groups_.size() * sizeof(std::uint64_t);
    }

private:
    FieldShape s_;
    std::array<int, 3> bricks_{};
    const std::uint64_t* dense_ = nullptr;
    const std::uint64_t* sign_ = nullptr;
    const std::uint64_t* nodes_ = nullptr;
    std::vector<std::uint32_t> rank_;    // dense bricks before each bitmap word
    std::vector<std::uint64_t> voxels_;  // per dense brick: its voxels with a corner <= 0
    std::array<int, 3> supers_{};        // groups of 4^3 bricks
    std::vector<std::uint64_t> groups_;  // per group: its bricks that are dense or inside
    double inv_g_ = 1;

    // The group of brick (i, j, k), and the brick's bit in the group's mask.
    std::uint64_t group_of(int i, int j, int k) const {
        return (std::uint64_t(k / kBrick) * std::uint64_t(supers_[1]) + std::uint64_t(j / kBrick)) *
                   std::uint64_t(supers_[0]) +
               std::uint64_t(i / kBrick);
    }
    static int brick_bit(int i, int j, int k) {
        return ((k % kBrick) * kBrick + j % kBrick) * kBrick + i % kBrick;
    }
    // The dense index of brick (i, j, k), or -1 when it is not dense.
    std::int64_t dense_index(int i, int j, int k) const;
    bool inside_brick(int i, int j, int k) const;
    double node_distance(std::uint64_t brick, int li, int lj, int lk) const;
    Vec3 node_normal(std::uint64_t brick, int li, int lj, int lk) const;
    // The field at node coordinates p: its value, and its normal when `n` is set.
    double value_at(Vec3 p, Vec3* n) const;
    // The first zero in voxel v of the segment in [t0, t1]; sets t and the normal.
    bool voxel_root(std::uint64_t brick, const std::array<int, 3>& v, const FieldSegment& g,
                    double t0, double t1, TableHit& out) const;
    bool march_brick(std::uint64_t brick, const std::array<int, 3>& b, const FieldSegment& g,
                     double t0, double t1, TableHit& out) const;
    // Marches the bricks of group s (4^3 bricks) that the segment meets in [t0, t1].
    bool march_group(const std::array<int, 3>& s, const FieldSegment& g, double t0, double t1,
                     TableHit& out) const;
};

}  // namespace lat
