#pragma once
// The acceleration structure: Embree 3 over the scene's objects. Every object is Embree user
// geometry whose callbacks intersect in double precision with the exact (double) ray, so Embree
// only prunes. Shapes made of several parts (sphere/cylinder chains) become one prototype scene
// each, placed by Embree instances, or are flattened (see Instancing); unbounded objects
// (half-spaces, paraboloids) live in a list tested directly, since a BVH cannot bound them.
#include <memory>
#include <span>
#include <vector>

#include "coverage/layer_sink.h"
#include "geometry/shape.h"
#include "math/transform.h"

namespace lat {

struct AccelObject {
    const Shape* shape = nullptr;  // must outlive the accelerator
    const Transform* xf = nullptr;  // object -> world; read only while the accelerator is built
    // The widest footprint (object units) of the rays the object is traced with, for shapes
    // whose culling narrows with it (CullParts::cull_bounds; lattices answered by sub-rays): each
    // instance gets its own, from how near the camera it stands. Infinity: any.
    double widest_footprint = kInfinity;
};

// The objects to place, as AccelObject says, read one by one while the accelerator is built
// and never after: a caller may make each transform when asked (a scene's scattered instances
// keep only their forward maps). The accelerator keeps each object's inverse map itself.
class AccelObjects {
public:
    virtual ~AccelObjects() = default;
    virtual std::size_t size() const = 0;
    virtual const Shape* shape(std::size_t i) const = 0;  // must outlive the accelerator
    virtual Transform transform(std::size_t i) const = 0;
    virtual double widest_footprint(std::size_t) const { return kInfinity; }
};

// Multi-part objects (chains) can be placed as Embree instances of one prototype scene each, or
// flattened: every part of every object in one world-space hierarchy with tight bounds. The
// flat form traces the paper's plates 1.6x faster (fewer, tighter boxes, no instance
// transforms in traversal); instancing keeps memory flat for huge instance counts.
enum class Instancing { kAuto, kAlways, kNever };

struct AccelOptions {
    Instancing instancing = Instancing::kAuto;
    // kAuto flattens while the total number of flattened parts stays within this.
    std::size_t flatten_budget = 4'000'000;
    // Objects culled by several parts (lattices: a box or capsule per stretch of the
    // primitive) enter the hierarchy as one primitive per part while their parts number at
    // most this in all, else as one primitive each, bounded by their parts together: at scale
    // the hierarchy's memory and build time follow the number of primitives.
    std::size_t cull_part_budget = 2'000'000;
    // A progress bar on stderr for a build that takes longer than a second.
    bool progress = false;
};

// A crossing found by a query: the object, under the number the caller gave it.
using AccelHit = ObjectHit;

class EmbreeAccel {
public:
    explicit EmbreeAccel(const AccelObjects& objects, const AccelOptions& opt = {});
    explicit EmbreeAccel(std::span<const AccelObject> objects, const AccelOptions& opt = {});

    ~EmbreeAccel();
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    // Closest crossing with tmin < t < tmax, over all objects.
    bool intersect(const Ray& r, double tmin, double tmax, AccelHit& hit) const;
    static constexpr std::uint32_t kNoObject = 0xFFFFFFFFu;
    // What blocked the last shadow ray of a run (one light's, pixel after pixel), which
    // occluded() and intersect_layers() (a shadow ray's transmittance) test first when the
    // caller keeps one: neighbouring pixels' shadow rays are mostly blocked by the same thing.
    // Only what is cheap to test is kept: a part of a several-part object (a strand's sphere or
    // cylinder, a triangle), or an object placed whole whose test costs at most
    // kCheapBlockerCost simple tests (a lattice's table, a sphere). The answer is the same with
    // or without it. Where shadows are too fine for runs (grass: 6 % of such tests blocked),
    // its trust falls to 0 and it is no longer tested first, until it blocks a ray again.
    // It belongs to one accelerator (the renderer keeps one per light in each tile's
    // ShadeState).
    struct LastBlocker {
        std::uint32_t object = kNoObject;  // the accelerator's own number
        std::uint32_t part = kWhole;       // its part, or kWhole
        // Tested first while above 0: full again (kMaxTrust) when it blocks a ray, tested first
        // or not; one less each time it is tested in vain.
        std::uint8_t trust = kMaxTrust;
        bool same(const LastBlocker& b) const { return object == b.object && part == b.part; }
    };
    static constexpr std::uint32_t kWhole = 0xFFFFFFFFu;
    static constexpr double kCheapBlockerCost = 1;
    static constexpr std::uint8_t kMaxTrust = 3;
    // Whether anything is crossed with tmin < t < tmax. A ray leaving a surface of object
    // `self` also skips that object's crossings within its surface_tolerance().
    bool occluded(const Ray& r, double tmin, double tmax, std::uint32_t self = kNoObject,
                  LastBlocker* last = nullptr) const;
    // One traversal for rays that see through partial crossings (Crossing::coverage < 1, from
    // lattices answered through a footprint): `hit`, as intersect() finds it, is the closest
    // opaque crossing, and `partial` every partial crossing before it, in ray order, as a
    // LayerSink with `stop` keeps them (coverage/layer_sink.h). `self` as for occluded().
    // last: for shadow rays (stop.shadow()), as for occluded().
    bool intersect_layers(const Ray& r, double tmin, double tmax, std::uint32_t self, AccelHit& hit,
                          std::vector<AccelHit>& partial, const LayerStop& stop = {},
                          LastBlocker* last = nullptr) const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace lat
