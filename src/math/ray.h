#pragma once
#include "math/vec.h"

namespace lat {

// A ray o + t d. The direction need not be unit length: affine maps keep t unchanged.
struct Ray {
    Vec3 o;
    Vec3 d;

    constexpr Vec3 at(double t) const { return o + d * t; }
};

}  // namespace lat
