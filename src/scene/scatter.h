#pragma once
// "scatter" objects: many instances of a primitive placed over the surface of another object
// (sphere, ellipsoid, any named quadric within a box, torus, half-space patch, triangle mesh),
// area-uniformly or as Poisson-disk (blue) noise, deterministically for a seed. The loader
// expands each scatter into a group of instances (ScatterGroup: their placements in an array),
// which both render modes trace as any other instance. docs/scene-format.md describes the fields.
#include <cstddef>
#include <vector>

#include "scene/json_reader.h"
#include "scene/object_parser.h"
#include "scene/scene.h"

namespace lat {

// Far more instances than a render wants. Memory is the real limit: a scatter is refused
// when its instances, with those placed before it, would take more than the memory available
// at kScatterBytesPerInstance each (about the most an instance costs, loaded and traced, in
// any mode: docs/scene-format.md).
constexpr std::size_t kMaxScatterCount = 50'000'000;
constexpr std::size_t kScatterBytesPerInstance = 1000;

// Where an instance of the primitive stands, in its coordinates: the centre of the bottom of its
// lattice box (or of its bounds). A scatter puts this point on the surface.
Vec3 primitive_root(const Primitive& prim);

// Expands the scatter `v` over the surface object `on` (its JSON, already parsed once as an
// object of the scene), into the group `out` (its name, place in the file and numbering are
// the caller's). before: how many objects the scene holds already. progress: a bar on stderr
// when placing them takes longer than a second.
void expand_scatter(const JsonValue& v, const JsonValue& on, const ObjectParser& parser,
                    const std::vector<Primitive>& primitives, std::size_t before,
                    ScatterGroup& out, bool progress = false);

}  // namespace lat
