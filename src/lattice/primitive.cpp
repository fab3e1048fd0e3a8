#include "lattice/primitive.h"

#include <algorithm>
#include <cassert>
#include <cstdio>

#include "util/error.h"

namespace lat {

void check_inside_box(const Primitive& p, const std::string& place) {
    assert(p.lattice);
    const Bounds3 b = p.shape->bounds();
    const double X = p.lattice->cells[0] * p.lattice->sigma,
                 Y = p.lattice->cells[1] * p.lattice->sigma,
                 Z = p.lattice->cells[2] * p.lattice->sigma;
    const double tol = 1e-9 * std::max({X, Y, Z});
    if (b.finite() && b.lo.x >= -tol && b.lo.y >= -tol && b.lo.z >= -tol && b.hi.x <= X + tol &&
        b.hi.y <= Y + tol && b.hi.z <= Z + tol)
        return;
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "primitive '%s' reaches outside its lattice box [0, %g] x [0, %g] x [0, %g] "
                  "(its bounds are [%g, %g] x [%g, %g] x [%g, %g])",
                  p.name.c_str(), X, Y, Z, b.lo.x, b.hi.x, b.lo.y, b.hi.y, b.lo.z, b.hi.z);
    throw InputError(place + buf);
}

}  // namespace lat
