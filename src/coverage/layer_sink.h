#pragma once
// Where a traversal through partial crossings puts what it meets, in the manner of Embree's
// filter functions: the accelerator (accel/embree_accel.h, intersect_layers) finds crossings
// and hands each partial one to a LayerSink, which keeps it or not and says whether the ray
// goes on and how far; the policy (how far compositing looks, when a shadow ray is blocked) is
// the sink's, not the accelerator's.
#include <cstdint>
#include <vector>

#include "coverage/layer_composite.h"
#include "coverage/sheets.h"

namespace lat {

// A crossing of one object along a ray: the object as the caller numbers it, the crossing in
// the object's coordinates (same t), and a sheet's sub-ray normals (coverage/sheets.h).
struct ObjectHit {
    double t = 0;
    std::uint32_t object = 0;
    Crossing crossing;
    SubRayNormals normals;
};

// Partial crossings in ray order, ties by object: the same for any traversal order.
inline bool in_ray_order(const ObjectHit& a, const ObjectHit& b) {
    return a.t != b.t ? a.t < b.t : a.object < b.object;
}

// How far a traversal through partial crossings needs to go.
struct LayerStop {
    // Shadow rays: once the partial crossings met let less than this through, or an opaque
    // one is met, the ray is blocked and the traversal ends at once (the closest crossing is
    // then not meant; only "blocked" is). 0: not a shadow ray.
    double blocked_below = 0;
    bool shadow() const { return blocked_below > 0; }
    // Camera rays, composited front to back: the partial crossings up to the max_layers-th
    // without sub-rays (LayerComposite::draws), or to where what they leave falls to min_left
    // or below, are all that is seen; the traversal looks no farther. max_layers 0: no limit.
    int max_layers = 0;
    double min_left = 0;
};

// The partial crossings of one ray, kept as `stop` says, in `partial` (cleared first).
class LayerSink {
public:
    LayerSink(std::vector<ObjectHit>& partial, const LayerStop& stop)
        : partial_(partial), stop_(stop) {
        partial_.clear();
    }

    bool shadow() const { return stop_.shadow(); }
    // An object answers a ray with its sheets at its first visit; met again (a traversal can
    // visit an object more than once), it is not counted twice.
    bool met_already(std::uint32_t object) const;
    // A shadow ray's partial crossing; whether the ray is now blocked. The stop has a margin
    // (1e-9 relative) that the product of what the crossings let through, taken in any order,
    // cannot close: transmittance then finds at most blocked_below in ray order too.
    bool add_shadow(const ObjectHit& h);
    // A camera ray's partial crossing: the crossings are kept in ray order and cut where
    // compositing will stop. Whether they were cut, and then tmax comes down to the last one
    // kept (so the traversal looks no farther).
    bool add_camera(const ObjectHit& h, double& tmax);
    // A partial crossing kept as it is (objects tested outside the traversal, whose order the
    // end puts right).
    void keep(const ObjectHit& h) { partial_.push_back(h); }
    // At the end of the traversal: partial crossings met before a closer opaque one was found
    // (at opaque_t, if `found`) lie behind it and go; the rest in ray order.
    void finish(bool found, double opaque_t);

private:
    std::vector<ObjectHit>& partial_;
    LayerStop stop_;
    LayerComposite transmitted_;  // a shadow ray's, which does not depend on the order
};

}  // namespace lat
