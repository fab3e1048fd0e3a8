#include "render/baselines/scene_parts.h"

namespace lat {
namespace {

Scene filtered(const Scene& scene, bool instances) {
    Scene out;
    out.file = scene.file;
    out.format = scene.format;
    out.camera = scene.camera;
    out.background = scene.background;
    out.ambient = scene.ambient;
    out.shadows = scene.shadows;
    out.lights = scene.lights;
    out.materials = scene.materials;
    out.primitives = scene.primitives;
    for (const SceneObject& o : scene.objects)
        if ((o.primitive >= 0) == instances) out.objects.push_back(o);
    if (instances) out.scatters = scene.scatters;
    out.number_scatters();
    return out;
}

}  // namespace

Scene base_scene(const Scene& scene) { return filtered(scene, false); }
Scene instance_scene(const Scene& scene) { return filtered(scene, true); }

std::vector<std::size_t> instance_objects(const Scene& scene) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < scene.object_count(); ++i)
        if (scene.primitive_of(i) >= 0) out.push_back(i);
    return out;
}

}  // namespace lat
