#pragma once
// The acceleration structure: Embree 3 over the scene's objects. Every object is Embree user
// geometry whose callbacks intersect in double precision with the exact (double) ray, so Embree
// only prunes. Shapes made of several parts (sphere/cylinder chains) become one prototype scene
// each, placed by Embree instances; unbounded objects (half-spaces, paraboloids) live in a list
// tested directly, since a BVH cannot bound them.
#include <memory>
#include <span>
#include <vector>

#include "geometry/shape.h"
#include "math/transform.h"

namespace lat {

struct AccelObject {
    const Shape* shape = nullptr;
    const Transform* xf = nullptr;  // object -> world; must outlive the accelerator
};

struct AccelHit {
    double t = 0;
    std::uint32_t object = 0;  // index into the objects given to the constructor
    Crossing crossing;         // in the object's coordinates (same t)
};

class EmbreeAccel {
public:
    explicit EmbreeAccel(std::span<const AccelObject> objects);
    ~EmbreeAccel();
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    // Closest crossing with tmin < t < tmax, over all objects.
    bool intersect(const Ray& r, double tmin, double tmax, AccelHit& hit) const;
    // Whether anything is crossed with tmin < t < tmax.
    bool occluded(const Ray& r, double tmin, double tmax) const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace lat
