#pragma once
// A scene as loaded from a file: plain data plus the shapes to trace (yocto-gl style).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/chain.h"
#include "geometry/shape.h"
#include "lattice/primitive.h"
#include "math/transform.h"

namespace lat {

struct Camera {
    Vec3 eye, look_at, up{0, 0, 1};
    double fov_y_deg = 45;
    int width = 512, height = 512;
};

struct PointLight {
    Vec3 position;
    Vec3 intensity{1, 1, 1};
};

struct Material {
    std::string name;
    Vec3 color{0.8, 0.8, 0.8};
    double ka = 0.1, kd = 0.7, ks = 0.2, shininess = 20;
};

struct SceneObject {
    std::shared_ptr<const Shape> shape;  // in object coordinates
    Transform xf;                        // object -> world
    std::uint32_t material = 0;          // CSG shapes carry their own per leaf
    int primitive = -1;                  // for instances: index into Scene::primitives
    std::string where;                   // e.g. "objects[12]", for messages
};

// A scatter object of the file, its instances numbered [first, first + count) among the scene's
// objects (Scene::object_count). They share their shape, material and place in the file; each
// keeps only its placement, object -> world in double (96 bytes), whose inverse is computed when
// it is wanted (Transform::from_affine gives the same bits as when the instance was placed). A
// million instances are 96 MB here, where whole SceneObjects would be 256 MB.
struct ScatterGroup {
    std::string name;        // its "name", or empty
    std::size_t json_index;  // in the file's "objects"
    std::size_t first = 0, count = 0;
    std::shared_ptr<const Shape> shape;  // the primitive's, in object coordinates
    std::uint32_t material = 0;
    int primitive = -1;  // index into Scene::primitives
    std::string where;   // e.g. "objects[12]", for messages
    std::vector<Affine> placements;
};

struct Scene {
    std::string file;
    std::string format;
    Camera camera;
    Vec3 background{0, 0, 0};
    Vec3 ambient{1, 1, 1};
    bool shadows = true;
    std::vector<PointLight> lights;
    std::vector<Material> materials;
    std::vector<Primitive> primitives;
    // The objects of the file and the scatters' instances: objects first, numbered from 0,
    // then each scatter's instances in turn. The accessors below read both by that number.
    std::vector<SceneObject> objects;
    std::vector<ScatterGroup> scatters;

    std::size_t object_count() const;
    // Object i whole (for instances, made from its group: a copy, for uses off the hot path).
    SceneObject object(std::size_t i) const;
    Transform transform(std::size_t i) const;  // object -> world
    // Starts reading what transform(i) reads into the cache: a ray's layers are met all over
    // a million instances' placements, and their misses overlap when started together.
    void prefetch_transform(std::size_t i) const;
    const std::shared_ptr<const Shape>& shape_of(std::size_t i) const;
    std::uint32_t material_of(std::size_t i) const;
    int primitive_of(std::size_t i) const;  // -1: not an instance
    const std::string& where_of(std::size_t i) const;
    // The group of object i, if it is a scatter's instance, with i made its index there.
    const ScatterGroup* group_of(std::size_t& i) const;
    // Numbers the groups after the objects (ScatterGroup::first, count).
    void number_scatters();
};

}  // namespace lat
