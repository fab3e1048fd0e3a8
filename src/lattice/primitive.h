#pragma once
// The lattice primitive (paper 2.1): a named small object that instances refer to, in the box
// of its lattice. Scenes define them (scene/); tables are built for them (lattice/cache/).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "geometry/shape.h"

namespace lat {

// The lattice around a primitive: box [0, nx*sigma] x [0, ny*sigma] x [0, nz*sigma].
struct LatticeSpec {
    double sigma = 1;
    std::array<int, 3> cells{1, 1, 1};
};

// A chain of spheres and cylinders, or any object (quartic, CSG) given as "object".
struct Primitive {
    std::string name;
    std::string where;  // e.g. "primitives.hair", for messages
    std::shared_ptr<const Shape> shape;
    std::uint64_t fingerprint = 0;  // of the geometry as written, to key lattice tables
    std::string definition;         // the geometry as written (JSON), stored with its tables
    std::optional<LatticeSpec> lattice;
};

// The primitive (with its lattice) must lie in its box: a table cannot see what sticks out,
// and a grid point inside a solid has no surface to answer with. InputError naming `place`
// (a prefix: "scene.json: primitives.hair: ") otherwise.
void check_inside_box(const Primitive& p, const std::string& place);

}  // namespace lat
