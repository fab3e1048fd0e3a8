#include "render/core/traced_scene.h"

#include <cassert>

#include "csg/csg_shape.h"

namespace lat {

namespace {

// The scene's objects as the accelerator reads them, with the shapes traced.
class SceneObjects final : public AccelObjects {
public:
    SceneObjects(const Scene& scene, const TracedScene& traced, std::span<const double> widest)
        : scene_(scene), traced_(traced), widest_(widest) {}
    std::size_t size() const override { return scene_.object_count(); }
    const Shape* shape(std::size_t i) const override {
        return &traced_.shape(static_cast<std::uint32_t>(i));
    }
    Transform transform(std::size_t i) const override { return scene_.transform(i); }
    double widest_footprint(std::size_t i) const override {
        return widest_.empty() ? kInfinity : widest_[i];
    }

private:
    const Scene& scene_;
    const TracedScene& traced_;
    std::span<const double> widest_;
};

}  // namespace

TracedScene::TracedScene(const Scene& scene, const InstanceShapeFn& instance_shape,
                         const AccelOptions& accel, std::span<const double> widest_footprints)
    : scene_(scene) {
    assert(widest_footprints.empty() || widest_footprints.size() == scene.object_count());
    object_shapes_.reserve(scene.objects.size());
    for (const SceneObject& o : scene.objects) {
        std::shared_ptr<const Shape> s = o.shape;
        if (o.primitive >= 0 && instance_shape) {
            s = instance_shape(o.primitive);
        } else if (o.shape && instance_shape) {
            if (auto swapped = csg_with_primitive_shapes(*o.shape, instance_shape)) s = swapped;
        }
        object_shapes_.push_back(std::move(s));
    }
    // A CSG tree's own, as traced (exactly, or with its instance leaves swapped for their
    // lattices); asked once for each run of objects of one shape.
    const Shape* asked = nullptr;
    std::span<const std::uint32_t> m;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        if (!object_shapes_[i]) continue;
        if (object_shapes_[i].get() != asked)
            asked = object_shapes_[i].get(), m = csg_surface_materials(*asked);
        if (m.empty()) continue;
        surface_materials_.resize(scene.objects.size());
        surface_materials_[i] = m;
    }
    for (const ScatterGroup& g : scene.scatters)
        group_shapes_.push_back(instance_shape ? instance_shape(g.primitive) : g.shape);
    accel_ = std::make_unique<EmbreeAccel>(SceneObjects(scene, *this, widest_footprints), accel);
}

const Shape& TracedScene::shape(std::uint32_t object) const {
    std::size_t i = object;
    if (const ScatterGroup* g = scene_.group_of(i))
        return *group_shapes_[static_cast<std::size_t>(g - scene_.scatters.data())];
    return *object_shapes_[object];
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
    if (found) scene_.prefetch_transform(h.object);
    for (const AccelHit& l : layers) scene_.prefetch_transform(l.object);
    if (found) surface_hit(r, h, hit);
    partial.resize(layers.size());
    for (std::size_t i = 0; i < layers.size(); ++i) surface_hit(r, layers[i], partial[i]);
    return found;
}

std::uint32_t TracedScene::material(std::uint32_t object, const Crossing& c) const {
    const std::uint32_t fallback = scene_.material_of(object);
    // Objects of scene.objects come first (Scene::object_count): a scatter's are past them.
    if (object >= surface_materials_.size()) return fallback;
    const std::span<const std::uint32_t> m = surface_materials_[object];
    const std::uint32_t s = c.leaf_index();
    return s < m.size() && m[s] != kNoMaterial ? m[s] : fallback;
}

void TracedScene::surface_hit(const Ray& r, const AccelHit& h, SurfaceHit& hit) const {
    const Transform xf = scene_.transform(h.object);
    const Shape& shape = this->shape(h.object);
    hit.t = h.t;
    hit.object = h.object;
    hit.part = h.crossing.part;
    hit.material = material(h.object, h.crossing);
    hit.alpha = static_cast<double>(h.crossing.coverage);
    hit.sub_rays = h.crossing.sub_rays;
    const SurfacePoint s = shape.surface(xf.is_identity() ? r : xf.inverse_ray(r), h.crossing);
    // Only a mean of normals (prefiltered lattices) is meant to be shorter than 1.
    const double len = length(s.n);
    hit.normal_length = len < 1 - 1e-6 ? len : 1.0;
    hit.normals = h.normals;
    if (xf.is_identity()) {
        hit.p = s.p;
        hit.n = hit.normal_length < 1 && len > 0 ? s.n / len : s.n;
    } else {
        hit.p = xf.point(s.p);
        hit.n = normalize(xf.normal(s.n));
        for (std::uint8_t k = 0; k < hit.normals.count; ++k)
            hit.normals.n[k] = normalize(xf.normal(hit.normals.n[k]));
    }
}

}  // namespace lat
