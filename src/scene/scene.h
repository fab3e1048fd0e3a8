#pragma once
// A scene as loaded from a file: plain data plus the shapes to trace (yocto-gl style).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/chain.h"
#include "geometry/shape.h"
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

// The lattice around a primitive: box [0, nx*sigma] x [0, ny*sigma] x [0, nz*sigma].
struct LatticeSpec {
    double sigma = 1;
    std::array<int, 3> cells{1, 1, 1};
};

// A named small object that instances refer to (paper: the lattice primitive): a chain of
// spheres and cylinders, or any object (quartic, CSG) given as "object".
struct Primitive {
    std::string name;
    std::string where;  // e.g. "primitives.hair", for messages
    std::shared_ptr<const Shape> shape;
    std::uint64_t fingerprint = 0;  // of the geometry as written, to key lattice tables
    std::string definition;         // the geometry as written (JSON), stored with its tables
    std::optional<LatticeSpec> lattice;
};

struct SceneObject {
    std::shared_ptr<const Shape> shape;  // in object coordinates
    Transform xf;                        // object -> world
    std::uint32_t material = 0;          // CSG shapes carry their own per leaf
    int primitive = -1;                  // for instances: index into Scene::primitives
    std::string where;                   // e.g. "objects[12]", for messages
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
};

}  // namespace lat
