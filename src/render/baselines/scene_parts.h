#pragma once
// The two halves of a furred scene that the texture and particle modes treat differently: the
// base (every object that is not an instance: spheres, meshes, quartics, CSG, even CSG with
// instance leaves) and the instances (top-level "instance" objects, scattered or written out).
#include <cstddef>
#include <vector>

#include "scene/scene.h"

namespace lat {

// The scene with its top-level instances removed (camera, lights and materials kept).
Scene base_scene(const Scene& scene);
// The scene with only its top-level instances.
Scene instance_scene(const Scene& scene);
// Numbers (Scene::object) of the top-level instances.
std::vector<std::size_t> instance_objects(const Scene& scene);

}  // namespace lat
