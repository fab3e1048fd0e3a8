#pragma once
// What is left of one ray after the partial crossings it met.
#include <bit>
#include <cstdint>

#include "coverage/sub_rays.h"
#include "geometry/shape.h"

namespace lat {

// Partial crossings of one ray composed: what is left of it after each, front to back (camera
// rays), or in any order (a shadow ray's transmittance, which does not depend on it).
// Crossings without sub-rays are taken as independent of the rest; those with sub-rays block
// only sub-rays not blocked already (coverage/sub_rays.h).
class LayerComposite {
public:
    // The share of what was left that a crossing of this coverage and these sub-rays
    // (Crossing::sub_rays) covers, and adds it.
    double add(double coverage, std::uint8_t sub_rays);
    double add(const Crossing& c) { return add(double(c.coverage), c.sub_rays); }
    // The share of the ray left.
    double left() const {
        return free_ * double(kSubRays - std::popcount(unsigned(covered_))) / kSubRays;
    }
    // How many crossings without sub-rays were added: what a limit on the layers of a ray
    // counts (one with sub-rays that blocks none not blocked already adds nothing, and all its
    // sub-rays blocked end a ray).
    int draws() const { return draws_; }

private:
    double free_ = 1;            // the product of (1 - coverage) of crossings without sub-rays
    std::uint8_t covered_ = 0;  // the sub-rays blocked
    int draws_ = 0;
};

}  // namespace lat
