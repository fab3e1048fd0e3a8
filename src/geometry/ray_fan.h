#pragma once
// Two rays from one origin in different directions tested against one part at once: the rays
// from a lattice's entry point to its exit points (rasterization). What a part's test derives
// from the origin alone is derived once, and the rest runs two rays to an SSE register. Each
// lane's arithmetic is the scalar test's, operation for operation (SSE2 rounds as scalar doubles
// do, and the build contracts nothing into FMA), so a lane's answer is the scalar intersect()'s
// bit for bit (ray_fan_test).
#include "geometry/ray_quad.h"

namespace lat {

struct RayFan {
    Vec3 o;             // the one origin
    quad::V3 d;         // the two directions
    quad::V tmin, tmax; // each ray's range, (tmin, tmax)
};

// What intersect() answers for the lanes whose bit the test returns: t and the part's own
// surface number (Crossing::part), as doubles.
struct FanHits {
    quad::V t, part;
};

}  // namespace lat
