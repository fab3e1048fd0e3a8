#include "accel/space_order.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <utility>

#include "math/bounds.h"

namespace lat {
namespace {

// The bits of v (below 2^10) spread to every third bit.
std::uint32_t spread_bits(std::uint32_t v) {
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    return (v | (v << 2)) & 0x09249249u;
}

// A Morton code of p's place in the box `within` (10 bits an axis).
std::uint32_t morton_code(Vec3 p, const Bounds3& within) {
    const Vec3 ext = within.extent();
    std::uint32_t code = 0;
    for (std::size_t k = 0; k < 3; ++k) {
        const double u = ext[k] > 0 ? (p[k] - within.lo[k]) / ext[k] : 0.0;
        const auto q = static_cast<std::uint32_t>((u > 0 ? std::min(u, 1.0) : 0.0) * 1023.0);
        code |= spread_bits(q) << k;
    }
    return code;
}

}  // namespace

std::vector<std::uint32_t> space_order(std::span<const Vec3> points) {
    Bounds3 all;
    for (const Vec3& p : points)
        if (is_finite(p)) all = merge(all, p);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> keys(points.size());
    for (std::uint32_t i = 0; i < points.size(); ++i)
        keys[i] = {is_finite(points[i]) ? morton_code(points[i], all) : ~0u, i};
    tbb::parallel_sort(keys.begin(), keys.end());  // the keys are distinct: one order
    std::vector<std::uint32_t> order;
    order.reserve(keys.size());
    for (const auto& key : keys) order.push_back(key.second);
    return order;
}

}  // namespace lat
