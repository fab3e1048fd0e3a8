#include "scene/scene.h"

#include <cassert>

namespace lat {

std::size_t Scene::object_count() const {
    std::size_t n = objects.size();
    for (const ScatterGroup& g : scatters) n += g.placements.size();
    return n;
}

const ScatterGroup* Scene::group_of(std::size_t& i) const {
    if (i < objects.size()) return nullptr;
    i -= objects.size();
    for (const ScatterGroup& g : scatters) {
        if (i < g.placements.size()) return &g;
        i -= g.placements.size();
    }
    assert(false && "object number past the scene's objects");
    return nullptr;
}

Transform Scene::transform(std::size_t i) const {
    const std::size_t object = i;
    if (const ScatterGroup* g = group_of(i)) {
        const std::optional<Transform> xf = Transform::from_affine(g->placements[i]);
        assert(xf);  // placed as a rotation times a positive scale: never singular
        return *xf;
    }
    return objects[object].xf;
}

void Scene::prefetch_transform(std::size_t i) const {
    if (const ScatterGroup* g = group_of(i)) {
        const char* p = reinterpret_cast<const char*>(&g->placements[i]);
        __builtin_prefetch(p);
        __builtin_prefetch(p + sizeof(Affine) - 1);
    }
}

const std::shared_ptr<const Shape>& Scene::shape_of(std::size_t i) const {
    const std::size_t object = i;
    if (const ScatterGroup* g = group_of(i)) return g->shape;
    return objects[object].shape;
}

std::uint32_t Scene::material_of(std::size_t i) const {
    const std::size_t object = i;
    if (const ScatterGroup* g = group_of(i)) return g->material;
    return objects[object].material;
}

int Scene::primitive_of(std::size_t i) const {
    const std::size_t object = i;
    if (const ScatterGroup* g = group_of(i)) return g->primitive;
    return objects[object].primitive;
}

const std::string& Scene::where_of(std::size_t i) const {
    const std::size_t object = i;
    if (const ScatterGroup* g = group_of(i)) return g->where;
    return objects[object].where;
}

SceneObject Scene::object(std::size_t i) const {
    const std::size_t object = i;
    const ScatterGroup* g = group_of(i);
    if (!g) return objects[object];
    return {g->shape, transform(object), g->material, g->primitive, g->where};
}

void Scene::number_scatters() {
    std::size_t first = objects.size();
    for (ScatterGroup& g : scatters) {
        g.first = first;
        g.count = g.placements.size();
        first += g.count;
    }
}

}  // namespace lat
