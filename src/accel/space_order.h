#pragma once
// Objects numbered along a space-filling curve, so that the ones a ray meets lie near each
// other in memory (accel/embree_accel.cpp).
#include <cstdint>
#include <span>
#include <vector>

#include "math/vec.h"

namespace lat {

// The indices of the points along a Morton curve through their bounding box; points that are
// not finite last.
std::vector<std::uint32_t> space_order(std::span<const Vec3> points);

}  // namespace lat
