#pragma once
// A scene made ready to trace (TracedScene): its objects' shapes behind the Embree
// accelerator, with the closest-hit query (intersect) and the cheaper any-hit query for shadow
// rays (occluded). The scene as read is Scene (scene/scene.h); the lattices that answer its
// instances are SceneLattices (render/modes/scene_lattices.h).
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "accel/embree_accel.h"
#include "scene/scene.h"

namespace lat {

struct SurfaceHit {
    double t = 0;
    Vec3 p;  // world position
    Vec3 n;  // outward unit normal, world space
    std::uint32_t material = 0;
    std::uint32_t object = 0;
    std::uint32_t part = 0;  // the shape's part that was hit (a mesh's triangle)
    double alpha = 1;  // coverage: below 1 only for lattices answered through a footprint (coverage/layers.h)
    std::uint8_t sub_rays = 0;  // which sub-rays the coverage is (Crossing::sub_rays)
    // Prefiltered lattices answer with the mean of the unit normals under a ray's footprint:
    // its length, below 1 where they diverge, widens the specular lobe (phong_term). 1 for
    // every other surface.
    double normal_length = 1;
    // A sheet of sub-rays' own unit normals (world space, SubRayNormals): shaded as the mean of
    // their terms, n standing for them where one normal is wanted.
    SubRayNormals normals;
};

class TracedScene {
public:
    // `instance_shape`, when given, supplies the shape traced for instances of primitive i
    // (e.g. its lattice); by default instances are traced exactly as their sphere/cylinder union.
    using InstanceShapeFn = std::function<std::shared_ptr<const Shape>(int primitive)>;
    // widest_footprints: per object, or empty (infinity), its AccelObject::widest_footprint.
    explicit TracedScene(const Scene& scene, const InstanceShapeFn& instance_shape = {},
                         const AccelOptions& accel = {},
                         std::span<const double> widest_footprints = {});

    bool intersect(const Ray& r, double tmin, double tmax, SurfaceHit& hit) const;
    // Through partial hits (render/layers.h): the closest opaque hit, if any, and every partial
    // hit before it, in ray order. `self` as for occluded.
    // stop: see EmbreeAccel::intersect_layers.
    bool intersect_layers(const Ray& r, double tmin, double tmax, std::uint32_t self,
                          SurfaceHit& hit, std::vector<SurfaceHit>& partial,
                          const LayerStop& stop = {}) const;
    // As intersect_layers, for a shadow ray's transmittance, which wants only what its
    // crossings cover: whether the ray is blocked (an opaque crossing, or partial ones that let
    // less than stop.blocked_below through), else its partial crossings, not made into surface
    // hits (their points and normals are not wanted).
    bool partial_crossings(const Ray& r, double tmin, double tmax, std::uint32_t self,
                           std::vector<AccelHit>& partial, const LayerStop& stop,
                           EmbreeAccel::LastBlocker* last = nullptr) const {
        AccelHit opaque;
        return accel_->intersect_layers(r, tmin, tmax, self, opaque, partial, stop, last);
    }
    // Every crossing a ray from outside the objects meets, not made into surface hits: the
    // closest opaque one (`opaque`, if any: the return) and the partial ones before it in ray
    // order, as `stop` keeps them (a deep shadow map's rays, render/deep_shadow_map.h).
    bool crossings(const Ray& r, double tmin, double tmax, std::vector<AccelHit>& partial,
                   AccelHit& opaque, const LayerStop& stop) const {
        return accel_->intersect_layers(r, tmin, tmax, EmbreeAccel::kNoObject, opaque, partial,
                                        stop);
    }
    // `self`: the object whose surface the ray leaves (see EmbreeAccel::occluded).
    bool occluded(const Ray& r, double tmin, double tmax,
                  std::uint32_t self = EmbreeAccel::kNoObject,
                  EmbreeAccel::LastBlocker* last = nullptr) const {
        return accel_->occluded(r, tmin, tmax, self, last);
    }

    const Scene& scene() const { return scene_; }
    // The shape traced for an object (its lattice, in lattice mode).
    const Shape& shape(std::uint32_t object) const;

private:
    const Scene& scene_;
    // As traced: per object of scene.objects, and per scatter group (its instances share it).
    std::vector<std::shared_ptr<const Shape>> object_shapes_, group_shapes_;
    // Per object of scene.objects, the materials of the surfaces its crossings number (a CSG
    // tree's leaves: csg_surface_materials), or empty: the object's material. Empty when no
    // object has any (a scatter's instances have none: they are primitives').
    std::vector<std::span<const std::uint32_t>> surface_materials_;
    std::unique_ptr<EmbreeAccel> accel_;

    void surface_hit(const Ray& r, const AccelHit& h, SurfaceHit& hit) const;
    // The material of crossing c of object i.
    std::uint32_t material(std::uint32_t object, const Crossing& c) const;
};


}  // namespace lat
