#include "render/core/traced_scene.h"

#include <cassert>

#include "csg/csg_shape.h"

namespace lat {

TracedScene::TracedScene(const Scene& scene, const InstanceShapeFn& instance_shape,
                         const AccelOptions& accel, std::span<const double> widest_footprints)
    : scene_(scene) {
    assert(widest_footprints.empty() || widest_footprints.size() == scene.objects.size());
    shapes_.reserve(scene.objects.size());
    for (const SceneObject& o : scene.objects) {
        std::shared_ptr<const Shape> s = o.shape;
        if (o.primitive >= 0 && instance_shape) {
            s = instance_shape(o.primitive);
        } else if (o.shape && instance_shape) {
            if (auto swapped = csg_with_primitive_shapes(*o.shape, instance_shape)) s = swapped;
        }
        shapes_.push_back(std::move(s));
    }
    // A CSG tree's own, as traced (exactly, or with its instance leaves swapped for their
    // lattices); asked once for each run of objects of one shape (instances).
    const Shape* asked = nullptr;
    std::span<const std::uint32_t> m;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        if (!shapes_[i]) continue;
        if (shapes_[i].get() != asked) asked = shapes_[i].get(), m = csg_surface_materials(*asked);
        if (m.empty()) continue;
        surface_materials_.resize(scene.objects.size());
        surface_materials_[i] = m;
    }
    accel_objects_.reserve(scene.objects.size());
    for (std::size_t i = 0; i < scene.objects.size(); ++i)
        accel_objects_.push_back({shapes_[i].get(), &scene.objects[i].xf,
                                  widest_footprints.empty() ? kInfinity : widest_footprints[i]});
    accel_ = std::make_unique<EmbreeAccel>(accel_objects_, accel);
}

bool TracedScene::intersect(const Ray& r, double tmin, double tmax, SurfaceHit& hit) const {
    AccelHit h;
    if (!accel_->intersect(r, tmin, tmax, h)) return false;
    surface_hit(r, h, hit);
    return true;
}

bool TracedScene::intersect_layers(const Ray& r, double tmin, double tmax, std::uint32_t self,
                                   SurfaceHit& hit, std::vector<SurfaceHit>& partial,
                                   const LayerStop& stop) const {
    AccelHit h;
    thread_local std::vector<AccelHit> layers;
    const bool found = accel_->intersect_layers(r, tmin, tmax, self, h, layers, stop);
    if (found) surface_hit(r, h, hit);
    partial.resize(layers.size());
    for (std::size_t i = 0; i < layers.size(); ++i) surface_hit(r, layers[i], partial[i]);
    return found;
}

std::uint32_t TracedScene::material(std::uint32_t object, const Crossing& c) const {
    const std::uint32_t fallback = scene_.objects[object].material;
    if (surface_materials_.empty()) return fallback;
    const std::span<const std::uint32_t> m = surface_materials_[object];
    const std::uint32_t s = c.leaf_index();
    return s < m.size() && m[s] != kNoMaterial ? m[s] : fallback;
}

void TracedScene::surface_hit(const Ray& r, const AccelHit& h, SurfaceHit& hit) const {
    const SceneObject& o = scene_.objects[h.object];
    const Shape& shape = *shapes_[h.object];
    hit.t = h.t;
    hit.object = h.object;
    hit.part = h.crossing.part;
    hit.material = material(h.object, h.crossing);
    hit.alpha = static_cast<double>(h.crossing.coverage);
    hit.sub_rays = h.crossing.sub_rays;
    const SurfacePoint s = shape.surface(o.xf.is_identity() ? r : o.xf.inverse_ray(r), h.crossing);
    // Only a mean of normals (prefiltered lattices) is meant to be shorter than 1.
    const double len = length(s.n);
    hit.normal_length = len < 1 - 1e-6 ? len : 1.0;
    hit.normals = h.normals;
    if (o.xf.is_identity()) {
        hit.p = s.p;
        hit.n = hit.normal_length < 1 && len > 0 ? s.n / len : s.n;
    } else {
        hit.p = o.xf.point(s.p);
        hit.n = normalize(o.xf.normal(s.n));
        for (std::uint8_t k = 0; k < hit.normals.count; ++k)
            hit.normals.n[k] = normalize(o.xf.normal(hit.normals.n[k]));
    }
}

}  // namespace lat
