#pragma once
// What the accelerator's callbacks read (accel/embree_accel.cpp): an object as placed, and the
// state of one query, which Embree hands them as its intersect context.
#include <embree3/rtcore.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "accel/embree_accel.h"
#include "accel/embree_rays.h"
#include "coverage/layer_sink.h"
#include "coverage/sheets.h"
#include "coverage/sub_rays.h"
#include "geometry/parts.h"

namespace lat::embree_detail {

// An object as the callbacks read it. The accelerator numbers its objects in the order of a
// space-filling curve through their boxes, and keeps what a callback loads in this record:
// the objects a ray meets are near each other, and their records then share cache lines
// (scattered objects come in random order, and a callback stalled on loading the object's
// shape and inverse map from the scene's records).
struct Placed {
    const Shape* shape;
    const SheetSource* sheets;  // the shape's, if it has more than its closest crossing to give
    const Parts* parts;         // the shape's, if it has several parts (geometry/parts.h)
    const CullParts* cull;      // the shape's, if it is culled by parts of its own
    Affine inverse;             // its transform's inverse map (world -> object)
    double widest_footprint;
    std::uint32_t original;  // its index among the objects given to the constructor
    bool identity;           // its transform is the identity
    bool similar;            // keeps_directions_across(its transform)
    // Placed as direct primitives (one Embree primitive per cull part, whose callbacks test
    // the whole shape), so that a shadow ray leaving it can test it after the traversal
    // instead (test_self_last). Culling is conservative, so the test unculled answers as the
    // callbacks' would.
    bool direct = false;
    // A direct object cheap enough to test before a shadow ray's traversal (LastBlocker).
    bool cheap_blocker = false;

    // r in the object's space, with footprint f (the query's object copy, or none).
    Ray local_ray(const Ray& r, const RayFootprint* f) const {
        return {inverse.point(r.o), inverse.vector(r.d), f};
    }
};

// Per-query state. Embree hands our callbacks the RTCIntersectContext; ours extends it with
// the double-precision ray and the best hit so far (the documented way to pass query data).
// Objects go by two numbers: the accelerator's (an index into Impl::objects: self, the cache
// and the ring of tested objects) and the caller's (AccelHit::object: hit, partial).
struct QueryContext {
    // h: where the closest hit goes (for a shadow ray's transmittance, what blocked it); null
    // for plain occlusion, which needs none.
    // framed: r in the accelerator's float frame (EmbreeAccel::Impl::in_frame).
    QueryContext(const EmbreeAccel::Impl& m, const Ray& r, const Ray& framed, double t0, double t1,
                 AccelHit* h)
        : accel(&m), ray(r), framed_o(framed.o), tmin(t0), tmax(t1), hit(h) {
        rtcInitIntersectContext(&rtc);
        if (!r.footprint) return;
        object_footprint.width0 = r.footprint->width0;
        object_footprint.spread = r.footprint->spread;
        object_footprint.coverage_only = r.footprint->coverage_only;
        object_footprint.seen_until = r.footprint->seen_until;
        local_footprint = &object_footprint;
    }
    QueryContext(const QueryContext&) = delete;
    QueryContext& operator=(const QueryContext&) = delete;

    RTCIntersectContext rtc;
    const EmbreeAccel::Impl* accel;
    Ray ray;  // world space, double
    Vec3 framed_o;  // its origin in the accelerator's float frame, for the float capsules
    // The ray's footprint in the space of the object being tested: its width, spread and
    // purpose the world ray's, its directions across and bound handed on per object
    // (hand_across; between, the last object's). Every object-space ray handed to a shape
    // points at it (local_footprint) when the world ray has a footprint, else carries none.
    RayFootprint object_footprint;
    const RayFootprint* local_footprint = nullptr;
    // Before object o is tested: its copy of the directions across the ray and its bound.
    void hand_across(const Placed& o) {
        if (local_footprint)
            across_in_object(*ray.footprint, o.inverse, o.identity, o.similar, o.widest_footprint,
                             object_footprint);
    }
    double tmin, tmax;
    AccelHit* hit;
    bool found = false;
    // Occlusion: the object the ray leaves (the accelerator's number); what was tested before
    // the traversal (LastBlocker), which its callbacks skip; what blocked the ray, if it is to
    // be kept (Impl::blocker_of).
    std::uint32_t self = EmbreeAccel::kNoObject;
    EmbreeAccel::LastBlocker tested_first, blocker;
    // intersect_layers: where crossings of partial coverage go (they do not end the ray), and
    // the policy that says how far to look; null for the other queries.
    LayerSink* sink = nullptr;
    // A shadow ray's transmittance (intersect_layers with LayerStop::blocked_below).
    bool shadow() const { return sink && sink->shadow(); }
    // The last object's object-space ray: consecutive parts of one object reuse it.
    std::uint32_t cached_obj = ~0u;
    Ray cached_local;
    // The object whose directions across the ray were handed on last.
    std::uint32_t across_obj = ~0u;
    // Objects culled by several parts that this query has already tested: a second part of
    // the same object can add nothing (its answer for a shorter range is no closer). A small
    // ring; an object that falls out of it is merely tested again.
    std::uint32_t tested[8];
    unsigned n_tested = 0;
    bool tested_already(std::uint32_t obj) const {
        const unsigned n = std::min(n_tested, 8u);
        for (unsigned i = 0; i < n; ++i)
            if (tested[i] == obj) return true;
        return false;
    }
    void mark_tested(std::uint32_t obj) { tested[n_tested++ % 8] = obj; }
};
// Callbacks cast Embree's context pointer back to ours.
static_assert(std::is_standard_layout_v<QueryContext> && offsetof(QueryContext, rtc) == 0);

// The object-space ray for objects tested outside Embree, with its footprint handed on.
inline Ray object_ray(const Placed& o, QueryContext& ctx) {
    ctx.hand_across(o);
    return o.identity ? Ray{ctx.ray.o, ctx.ray.d, ctx.local_footprint}
                      : o.local_ray(ctx.ray, ctx.local_footprint);
}

}  // namespace lat::embree_detail
