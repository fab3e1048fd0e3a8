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

// A scatter object of the file, expanded into objects [first, first + count).
struct ScatterGroup {
    std::string name;        // its "name", or empty
    std::size_t json_index;  // in the file's "objects"
    std::size_t first = 0, count = 0;
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
    std::vector<SceneObject> objects;
    std::vector<ScatterGroup> scatters;
};

}  // namespace lat
