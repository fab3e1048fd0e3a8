#pragma once
// A few capsules tested against one line at once, in float, four to an SSE register: a screen
// in front of Capsule::meets_line. It names the capsules the line may meet, and never leaves
// out one whose own test (in double) accepts the line, so that running that test on the named
// ones alone gives every answer the plain loop gives (capsule_screen_test). Lattice culling
// asks it of every ray that meets an instance's box, most of which miss the hair's capsules:
// four capsules cost about what the division of one double test does.
#include <immintrin.h>

#include <cstdint>
#include <span>
#include <vector>

#include "geometry/shape.h"

namespace lat {

class CapsuleScreen {
public:
    static constexpr std::size_t kMaxCapsules = 32;

    CapsuleScreen() = default;
    // At most kMaxCapsules capsules of finite ends and radii (more, or others: an empty screen,
    // which names every capsule).
    explicit CapsuleScreen(std::span<const Capsule> capsules);

    bool empty() const { return count_ == 0; }
    // Bit k set for each capsule k whose test meets_line(o, d, c.r - narrower) may accept
    // the line o + t d (d non-zero): a capsule left out is certainly missed.
    std::uint32_t may_meet(Vec3 o, Vec3 d, double narrower = 0) const;

private:
    // Four capsules: their ends a (relative to centre_) and axes u = b - a, and radii.
    struct Group {
        __m128 ax, ay, az, ux, uy, uz, r;
    };
    std::vector<Group> groups_;
    std::size_t count_ = 0;
    Vec3 centre_;     // of the capsules' ends' box
    double extent_ = 0;  // the farthest end from centre_ (L1) twice, and the largest radius
};

}  // namespace lat
