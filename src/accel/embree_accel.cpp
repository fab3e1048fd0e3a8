#include "accel/embree_accel.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "accel/embree_query.h"
#include "accel/embree_rays.h"
#include "accel/space_order.h"
#include "geometry/lattice_source.h"
#include "math/float_round.h"
#include "util/progress.h"

namespace lat {

using namespace embree_detail;

namespace {

// Whether a map keeps the directions across a ray across it and as long as its direction (a
// similarity: turned and evenly scaled), within 1e-3 (scenes give rotations to 6 digits). A
// sheared or unevenly scaled object offsets its sub-rays along its own directions
// (coverage/sub_rays.h).
bool keeps_directions_across(const Transform& xf) {
    const Vec3 c[3] = {xf.vector({1, 0, 0}), xf.vector({0, 1, 0}), xf.vector({0, 0, 1})};
    const double s2 = dot(c[0], c[0]), tol = 1e-3 * s2;
    return std::abs(dot(c[1], c[1]) - s2) <= tol && std::abs(dot(c[2], c[2]) - s2) <= tol &&
           std::abs(dot(c[0], c[1])) <= tol && std::abs(dot(c[0], c[2])) <= tol &&
           std::abs(dot(c[1], c[2])) <= tol;
}

}  // namespace

struct EmbreeAccel::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<Placed> objects;          // in the accelerator's order (Placed)
    // Embree's float frame: world points less this, the centre of the boxes it holds, so that
    // its rounding (and the margin its bounds are grown by, to_rtc_bounds) goes with the
    // scene's size, not its distance from the world's origin. (Fur a million units out had its
    // hairs' boxes grown by 2 units each, and took 17 times as long.) The callbacks read the
    // world ray in double (QueryContext::ray), so only the float side moves.
    Vec3 frame;
    Ray in_frame(const Ray& r) const { return {r.o - frame, r.d, r.footprint}; }
    RTCBounds held_bounds(const Bounds3& b) const {
        return to_rtc_bounds({b.lo - frame, b.hi - frame});
    }
    // The centre of the boxes Embree will hold (embree_can_hold); the origin if none.
    static Vec3 frame_of(const std::vector<Bounds3>& bounds) {
        Bounds3 held;
        for (const Bounds3& b : bounds)
            if (!b.empty() && embree_can_hold(b)) held = merge(held, b);
        return held.empty() ? Vec3{} : held.center();
    }
    std::vector<std::uint32_t> numbered;  // an object's index given -> its index in objects
    // A crossing of objects[obj], under the number the caller gave the object.
    AccelHit caller_hit(double t, std::uint32_t obj, const Crossing& c) const {
        return {t, objects[obj].original, c, {}};
    }
    // The index in objects of the object the caller numbers given_self (kNoObject: none).
    std::uint32_t our_number(std::uint32_t given_self) const {
        return given_self < numbered.size() ? numbered[given_self] : EmbreeAccel::kNoObject;
    }
    // A shape's interfaces, asked once for a run of objects of that shape (instances come
    // together): asking costs a cross-cast each.
    struct ShapeRoles {
        const Shape* shape = nullptr;
        const SheetSource* sheets = nullptr;
        const Parts* parts = nullptr;
        const CullParts* cull = nullptr;
        void ask(const Shape& s) {
            if (&s == shape) return;
            shape = &s, sheets = sheet_source(s), parts = parts_of(s), cull = cull_parts_of(s);
        }
    };
    // The objects given, while the accelerator is built (AccelObjects), and the build's number.
    const AccelObjects* given = nullptr;
    std::uint64_t build = 0;
    Transform transform_of(std::uint32_t obj) const { return given->transform(objects[obj].original); }
    // Fills objects with the objects given, in the order of a Morton curve through the centres
    // of their world boxes (empty and unbounded ones last), and bounds with their bounds in the
    // hierarchy: their world boxes, or for objects entered whole (enter_whole, set before)
    // whole_bounds. Each object's transform is made once, in the order given (a scene's
    // placements are read in turn), and the records are then put in space order.
    void number_objects(std::vector<Bounds3>& bounds) {
        const std::size_t n = given->size();
        objects.resize(n);
        bounds.resize(n);
        std::vector<Vec3> centres(n);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const auto& range) {
            ShapeRoles roles;
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
                const Shape* shape = given->shape(i);
                roles.ask(*shape);
                const Transform xf = given->transform(i);
                Placed& o = objects[i];
                o = {shape, roles.sheets, roles.parts, roles.cull, xf.inverse_map(),
                     given->widest_footprint(i), static_cast<std::uint32_t>(i),
                     xf.is_identity(), keeps_directions_across(xf)};
                Bounds3 b = shape->placed_bounds(xf);
                const bool held = embree_can_hold(b) && !b.empty();
                centres[i] = held ? b.center() : Vec3{kInfinity, 0, 0};
                if (held && enter_whole && enters_whole(o)) b = whole_bounds(o, xf, b);
                bounds[i] = b;
            }
        });
        const std::vector<std::uint32_t> order = space_order(centres);
        centres = {};
        numbered.resize(n);
        tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) {
            numbered[order[k]] = static_cast<std::uint32_t>(k);
        });
        objects = in_order(objects, order);
        bounds = in_order(bounds, order);
    }
    // v[order[0]], v[order[1]], ...: gathered in parallel (the reads fall at random in v),
    // one vector at a time, so that the copy is never more than one vector's size.
    template <class T>
    static std::vector<T> in_order(const std::vector<T>& v, const std::vector<std::uint32_t>& order) {
        std::vector<T> out(v.size());
        tbb::parallel_for(std::size_t{0}, v.size(), [&](std::size_t k) { out[k] = v[order[k]]; });
        return out;
    }
    // The top-level user geometry of single-part objects: one primitive per cull part
    // (CullParts::cull_count).
    // Read on every callback, so kept small: 36 bytes, the bounds (read only while Embree
    // builds) apart. Its loads are the callbacks' main cost (cache misses): with the capsule in
    // double beside the bounds, its test saved grass 4 % of its time; this way, 5 %.
    struct DirectPrim {
        std::uint32_t object;
        std::uint32_t cull : 31;   // the object's cull part
        std::uint32_t shared : 1;  // one of several cull parts of its object
        FloatCapsule capsule;      // CullParts::cull_capsule, if it has one
    };
    static_assert(sizeof(DirectPrim) == 36);
    // Its capsule in float, in the frame (in world space it would be rounded to the world's
    // float steps, far from the origin).
    DirectPrim direct_prim(std::uint32_t object, std::uint32_t cull, bool shared,
                           const Placed& o, const Transform& xf) const;
    std::vector<DirectPrim> direct;
    std::vector<RTCBounds> direct_bounds;    // world space, per direct primitive; build only
    std::vector<std::uint32_t> unbounded;    // objects tested outside Embree
    std::vector<std::uint32_t> inst_object;  // top-level geomID -> object, for instances
    struct FlatPrim {
        std::uint32_t object, part;
    };
    std::vector<FlatPrim> flat;  // parts of multi-part objects placed directly in world space
    bool flatten = false;
    // Objects of several cull parts enter as one primitive each (place_whole): past
    // AccelOptions::cull_part_budget.
    bool enter_whole = false;
    std::map<const Parts*, RTCScene> prototypes;  // one scene per shape of several parts
    std::string error;

    ~Impl() {
        for (auto& [parts, s] : prototypes) rtcReleaseScene(s);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    // The start of an occlusion test against object obj (see EmbreeAccel::occluded).
    double occlusion_tmin(const QueryContext* ctx, std::uint32_t obj, const Ray& local) const {
        if (obj != ctx->self) return ctx->tmin;
        const double tol = objects[obj].shape->surface_tolerance();
        return tol > 0 ? ctx->tmin + tol / length(local.d) : ctx->tmin;
    }

    // The object-space ray: consecutive callbacks for one object reuse it.
    const Ray& local_ray(QueryContext* ctx, std::uint32_t obj) const {
        if (ctx->cached_obj != obj) {
            ctx->cached_obj = obj;
            ctx->cached_local = objects[obj].local_ray(ctx->ray, ctx->local_footprint);
        }
        return ctx->cached_local;
    }
    // Before an object is tested: the directions across the ray in its space handed on
    // (QueryContext::object_footprint), only when the object changes (within a traversal
    // nothing else sets them), and not for the many objects that culling rejects.
    void hand_across(QueryContext* ctx, std::uint32_t obj) const {
        if (ctx->across_obj == obj) return;
        ctx->across_obj = obj;
        ctx->hand_across(objects[obj]);
    }

    // Whether a direct primitive's object is to be tested: it was not tested already for this
    // query, and the line meets the cull part, first its capsule in world space (before the
    // object's transform is loaded; on grass it rejects 2.8 of 5.8 million callbacks), then
    // in the shape's own space (first_visit: another 2.1 million).
    bool may_visit(QueryContext* ctx, unsigned prim) const {
        const DirectPrim& d = direct[prim];
        if (!d.shared) return true;
        return !ctx->tested_already(d.object) && d.capsule.meets_line(ctx->framed_o, ctx->ray.d);
    }
    bool first_visit(QueryContext* ctx, unsigned prim, const Ray& local) const {
        const DirectPrim& d = direct[prim];
        if (!d.shared) return true;
        // Only shapes of several cull parts share them.
        assert(objects[d.object].cull);
        const CullParts& cull = *objects[d.object].cull;
        if (d.cull == kEveryPart) {
            if (!cull.cull_meets_any(local)) return false;
        } else if (!cull.cull_meets(d.cull, local)) {
            return false;
        }
        ctx->mark_tested(d.object);
        return true;
    }
    // An object entered whole (place_whole): its cull parts tested in its own space, the
    // shape's (CullParts::cull_meets_any), so that they cost the instance nothing.
    static constexpr std::uint32_t kEveryPart = 0x7FFFFFFFu;

    void record(QueryContext* ctx, RTCRayHit* rh, std::uint32_t obj, const Crossing& c,
                unsigned geom, unsigned prim, unsigned inst) const {
        assert(ctx->hit);  // closest-hit queries only (plain occlusion queries have none)
        ctx->found = true;
        *ctx->hit = caller_hit(c.t, obj, c);
        rh->ray.tfar = float_above(c.t);
        rh->hit.geomID = geom;
        rh->hit.primID = prim;
        rh->hit.instID[0] = inst;
        rh->hit.Ng_x = 0;
        rh->hit.Ng_y = 0;
        rh->hit.Ng_z = 1;
        rh->hit.u = rh->hit.v = 0;
    }

    // The three kinds of user geometry: one primitive per object (direct), the parts of a
    // prototype placed by Embree instances (proto), and parts of objects in world space (flat).
    enum class Kind { kDirect, kProto, kFlat };
    struct Target {
        std::uint32_t object;
        std::size_t part;
    };
    template <Kind K>
    Target target(unsigned prim, unsigned inst) const {
        if constexpr (K == Kind::kDirect) return {direct[prim].object, 0};
        if constexpr (K == Kind::kProto) return {inst_object[inst], prim};
        return {flat[prim].object, flat[prim].part};
    }

    template <Kind K>
    static void intersect_cb(const RTCIntersectFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const unsigned inst = args->context->instID[0];
        const Target t = self->template target<K>(args->primID, inst);
        if constexpr (K == Kind::kDirect)
            if (!self->may_visit(ctx, args->primID)) return;
        const Placed& o = self->objects[t.object];
        const Ray& local = self->local_ray(ctx, t.object);
        if constexpr (K == Kind::kDirect)
            if (!self->first_visit(ctx, args->primID, local)) return;
        self->hand_across(ctx, t.object);
        assert(ctx->hit);         // rtcIntersect1 runs only for intersect and intersect_layers
        assert(!ctx->shadow());  // shadow rays: occluded_cb, blocks_transmittance
        const double tmax = ctx->found ? std::min(ctx->hit->t, ctx->tmax) : ctx->tmax;
        const double tmin = ctx->sink ? self->occlusion_tmin(ctx, t.object, local) : ctx->tmin;
        auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
        const unsigned geom = args->geomID, prim = args->primID;
        const unsigned placed = K == Kind::kProto ? inst : RTC_INVALID_GEOMETRY_ID;
        if constexpr (K == Kind::kDirect)
            if (ctx->sink)
                return self->add_sheets(ctx, rh, t.object, local, tmin, tmax, geom, prim);
        Crossing c;
        const bool hit = K == Kind::kDirect
                             ? o.shape->intersect(local, tmin, tmax, c)
                             : o.parts->intersect_part(t.part, local, tmin, tmax, c);
        // A shape of several parts (chains, meshes) is opaque: only a whole shape (a lattice)
        // answers with partial sheets.
        assert(!ctx->sink || c.coverage >= 1.0f || !hit);
        if (hit) self->record(ctx, rh, t.object, c, geom, prim, placed);
    }

    // A camera ray through partial crossings: the object's sheets (coverage/sheets.h), partial
    // ones handed to the sink (the ray goes on) unless a visit before this one handed them, in
    // ray order up to the first opaque one, recorded as the hit.
    void add_sheets(QueryContext* ctx, RTCRayHit* rh, std::uint32_t obj, const Ray& local,
                    double tmin, double tmax, unsigned geom, unsigned prim) const {
        // Per-thread scratch, not on the stack: 4 sheets' default values written at every
        // visit cost more than the visit of a shape that has one.
        thread_local std::array<SheetCrossing, kMaxSheets> sheets;
        const Placed& o = objects[obj];
        const int n = sheets_of(*o.shape, o.sheets, local, tmin, tmax, sheets);
        const bool met = n > 0 && ctx->sink->met_already(o.original);
        for (int i = 0; i < n; ++i) {
            const Crossing& c = sheets[static_cast<std::size_t>(i)].crossing;
            const SubRayNormals& normals = sheets[static_cast<std::size_t>(i)].normals;
            if (c.coverage < 1.0f) {
                if (met) continue;
                AccelHit h = caller_hit(c.t, obj, c);
                h.normals = normals;
                if (ctx->sink->add_camera(h, ctx->tmax))
                    rh->ray.tfar = std::min(rh->ray.tfar, float_above(ctx->tmax));
                continue;
            }
            record(ctx, rh, obj, c, geom, prim, RTC_INVALID_GEOMETRY_ID);
            ctx->hit->normals = normals;
            return;
        }
    }

    // A shadow ray's transmittance (intersect_layers with LayerStop::blocked_below), traced by
    // the any-hit traversal since its crossings compose in any order: whether this object
    // blocks it, opaque or with the partial crossings met so far letting too little through
    // (then written to the query's hit, as intersect_layers reads it).
    template <Kind K>
    bool blocks_transmittance(QueryContext* ctx, Target t, const Placed& o, const Ray& local,
                              double tmin) const {
        assert(ctx->hit && ctx->shadow());
        Crossing c;
        const bool hit = K == Kind::kDirect
                             ? o.shape->intersect(local, tmin, ctx->tmax, c)
                             : o.parts->intersect_part(t.part, local, tmin, ctx->tmax, c);
        if (!hit) return false;
        const AccelHit h = caller_hit(c.t, t.object, c);
        if (c.coverage < 1.0f && !ctx->sink->add_shadow(h)) return false;
        *ctx->hit = h;
        return true;
    }

    // A shadow ray's own object (the one it leaves) is tested after the traversal rather than
    // in it: when another object blocks the ray first it is never tested, and otherwise its
    // answer is the same (a transmittance's crossings compose in any order). (Grass: 41 % of
    // the shadow rays' sheet tests were of their own object, 1.2 % of them blocking.) Only a
    // direct object's: the direct callbacks are the ones that skip it.
    void test_self_last(QueryContext& ctx) const {
        if (ctx.found || ctx.self >= objects.size() || !objects[ctx.self].direct) return;
        const Placed& o = objects[ctx.self];
        const Ray local = object_ray(o, ctx);
        const double tmin = occlusion_tmin(&ctx, ctx.self, local);
        const Target t{ctx.self, 0};
        if (ctx.shadow())
            ctx.found = blocks_transmittance<Kind::kDirect>(&ctx, t, o, local, tmin);
        else
            ctx.found = o.shape->occluded(local, tmin, ctx.tmax);
        if (ctx.found) ctx.blocker = blocker_of<Kind::kDirect>(t);
    }

    // What a shadow ray's run keeps of what blocked it (EmbreeAccel::LastBlocker): a part of a
    // several-part object, or a direct object cheap to test; else nothing.
    template <Kind K>
    EmbreeAccel::LastBlocker blocker_of(Target t) const {
        if (K == Kind::kDirect && !objects[t.object].cheap_blocker) return {};
        return tested_as<K>(t);
    }
    // A target as a LastBlocker names it: a direct object whole, else its part.
    template <Kind K>
    static EmbreeAccel::LastBlocker tested_as(Target t) {
        if constexpr (K == Kind::kDirect) return {t.object, EmbreeAccel::kWhole};
        return {t.object, static_cast<std::uint32_t>(t.part)};
    }

    // Before a shadow ray's traversal: whether the run's blocker, kept and trusted, blocks this
    // ray too (EmbreeAccel::LastBlocker). Not the ray's own direct object, which test_self_last
    // tests after the traversal; what is tested here the traversal's callbacks skip.
    bool blocked_by_kept(QueryContext& ctx, EmbreeAccel::LastBlocker* last) const {
        if (!last || last->trust == 0 || last->object >= objects.size()) return false;
        const Placed& o = objects[last->object];
        const bool whole = last->part == EmbreeAccel::kWhole;
        assert(whole ? o.cheap_blocker : o.parts && last->part < o.parts->part_count());
        if (whole && last->object == ctx.self) return false;
        const Ray local = object_ray(o, ctx);
        const double tmin = occlusion_tmin(&ctx, last->object, local);
        bool blocked;
        if (ctx.shadow()) {  // a transmittance: a partial crossing it meets is kept
            const Target t{last->object, whole ? 0 : last->part};
            blocked = whole ? blocks_transmittance<Kind::kDirect>(&ctx, t, o, local, tmin)
                            : blocks_transmittance<Kind::kFlat>(&ctx, t, o, local, tmin);
        } else {
            blocked = whole ? o.shape->occluded(local, tmin, ctx.tmax)
                            : o.parts->occluded_part(last->part, local, tmin, ctx.tmax);
        }
        if (blocked) {
            last->trust = EmbreeAccel::kMaxTrust;
        } else {
            ctx.tested_first = *last;
            --last->trust;
        }
        return blocked;
    }
    // After the traversal: what blocked the ray (nothing, if it got through or what blocked it
    // is not kept) is the run's blocker from now on; if it was the kept one, not tested first
    // (it would have blocked the ray), it is trusted again.
    static void keep_blocker(const QueryContext& ctx, EmbreeAccel::LastBlocker* last) {
        if (!last) return;
        if (ctx.blocker.object != EmbreeAccel::kNoObject && last->same(ctx.blocker))
            last->trust = EmbreeAccel::kMaxTrust;
        last->object = ctx.blocker.object;
        last->part = ctx.blocker.part;
    }

    template <Kind K>
    static void occluded_cb(const RTCOccludedFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const Target t = self->template target<K>(args->primID, args->context->instID[0]);
        if constexpr (K == Kind::kDirect)
            if (t.object == ctx->self || !self->may_visit(ctx, args->primID)) return;
        if (ctx->tested_first.same(tested_as<K>(t))) return;
        const Placed& o = self->objects[t.object];
        const Ray& local = self->local_ray(ctx, t.object);
        if constexpr (K == Kind::kDirect)
            if (!self->first_visit(ctx, args->primID, local)) return;
        self->hand_across(ctx, t.object);
        const double tmin = self->occlusion_tmin(ctx, t.object, local);
        bool hit;
        if (ctx->shadow())
            hit = self->blocks_transmittance<K>(ctx, t, o, local, tmin);
        else if constexpr (K == Kind::kDirect)
            hit = o.shape->occluded(local, tmin, ctx->tmax);
        else
            hit = o.parts->occluded_part(t.part, local, tmin, ctx->tmax);
        if (hit) {
            ctx->found = true;
            ctx->blocker = self->template blocker_of<K>(t);
            reinterpret_cast<RTCRay*>(args->ray)->tfar = -INFINITY;
        }
    }

    static void bounds_flat(const RTCBoundsFunctionArguments* args) {
        const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
        const FlatPrim fp = self->flat[args->primID];
        // An object's parts come one after another: its transform is made once for them all
        // (kept by the build, whose number no later accelerator shares, unlike its address).
        thread_local std::uint64_t last_build = 0;
        thread_local std::uint32_t last_object = EmbreeAccel::kNoObject;
        thread_local Transform xf;
        if (last_build != self->build || last_object != fp.object) {
            xf = self->transform_of(fp.object);
            last_build = self->build;
            last_object = fp.object;
        }
        *args->bounds_o = self->held_bounds(self->objects[fp.object].parts->part_bounds(fp.part, xf));
    }

    static void bounds_direct(const RTCBoundsFunctionArguments* args) {
        const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
        *args->bounds_o = self->direct_bounds[args->primID];
    }

    static void bounds_proto(const RTCBoundsFunctionArguments* args) {
        const auto* parts = static_cast<const Parts*>(args->geometryUserPtr);
        *args->bounds_o = to_rtc_bounds(parts->part_bounds(args->primID));
    }

    // One user geometry of n primitives with these callbacks, attached to scene s.
    void attach_user_geometry(RTCScene s, std::size_t n, void* user, RTCBoundsFunction bounds,
                              RTCIntersectFunctionN intersect,
                              RTCOccludedFunctionN occluded) const {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(n));
        rtcSetGeometryUserData(g, user);
        rtcSetGeometryBoundsFunction(g, bounds, user);
        rtcSetGeometryIntersectFunction(g, intersect);
        rtcSetGeometryOccludedFunction(g, occluded);
        rtcCommitGeometry(g);
        rtcAttachGeometry(s, g);
        rtcReleaseGeometry(g);
    }

    // Object i, whose world box is wb: tested outside Embree (unbounded), its parts placed
    // flat, an Embree instance of its prototype, or one direct primitive per cull part.
    void place(std::uint32_t i, const Bounds3& wb) {
        Placed& o = objects[i];
        if (wb.empty()) return;
        if (!embree_can_hold(wb)) {
            unbounded.push_back(i);
        } else if (part_count(o) > 1 && flatten) {
            for (std::uint32_t p = 0; p < o.parts->part_count(); ++p) flat.push_back({i, p});
        } else if (part_count(o) > 1) {
            place_instance(i);
        } else if (enter_whole && enters_whole(o)) {
            place_whole(i, wb);
        } else {
            const ShapeCull cull = culled(o);
            const std::size_t parts = cull.cull_count();
            const Transform xf = transform_of(i);
            for (std::uint32_t c = 0; c < parts; ++c) {
                Bounds3 b = cull.cull_bounds(c, xf, o.widest_footprint);
                if (parts == 1) b = lat::intersect(wb, b);  // a lone part: within the object's box
                if (b.empty()) continue;
                direct.push_back(direct_prim(i, c, parts > 1, o, xf));
                o.direct = true;
                o.cheap_blocker = cheap_to_test(o);
                direct_bounds.push_back(held_bounds(b));
            }
        }
    }

    // Object i as one direct primitive bounded by the union of its cull parts' bounds; its
    // callbacks test the parts in the shape's space (first_visit). Its culling is as tight on
    // the ray's line, looser in the hierarchy, and its memory a ninth (a hair's 9 parts).
    // b: its bounds (whole_bounds).
    void place_whole(std::uint32_t i, const Bounds3& b) {
        Placed& o = objects[i];
        if (b.empty()) return;
        direct.push_back({i, kEveryPart, 1, {}});  // no capsule: every line meets it
        o.direct = true;
        o.cheap_blocker = cheap_to_test(o);
        direct_bounds.push_back(held_bounds(b));
    }

    // The object's parts and cull parts, through the interfaces asked once (Placed).
    static ShapeParts parted(const Placed& o) { return ShapeParts(*o.shape, o.parts); }
    static ShapeCull culled(const Placed& o) { return ShapeCull(*o.shape, o.cull); }
    static std::size_t part_count(const Placed& o) { return parted(o).part_count(); }
    // Asked of consecutive objects, which mostly share their shape (instances), once a shape.
    const Shape* cost_asked = nullptr;
    bool cost_cheap = false;
    bool cheap_to_test(const Placed& o) {
        if (o.shape != cost_asked) {
            cost_asked = o.shape;
            cost_cheap = ShapeSource(*o.shape).intersect_cost() <= EmbreeAccel::kCheapBlockerCost;
        }
        return cost_cheap;
    }

    // Whether an object of these parts would enter whole past the cull-part budget.
    static bool enters_whole(const ShapeParts& parts, const ShapeCull& cull) {
        return parts.part_count() <= 1 && cull.cull_count() > 1;
    }
    static bool enters_whole(const Placed& o) { return enters_whole(parted(o), culled(o)); }
    // The bounds of an object entered whole, placed by xf, whose world box is wb: its cull
    // parts' together.
    static Bounds3 whole_bounds(const Placed& o, const Transform& xf, const Bounds3& wb) {
        assert(o.cull);  // entered whole: several cull parts
        Bounds3 b;
        for (std::size_t c = 0; c < o.cull->cull_count(); ++c)
            b = merge(b, o.cull->cull_bounds(c, xf, o.widest_footprint));
        return lat::intersect(wb, b);
    }

    // Object i as an Embree instance of its shape's prototype scene.
    void place_instance(std::uint32_t i) {
        const Placed& o = objects[i];
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, prototype_scene(o.parts));
        const Affine a = transform_of(i).forward();
        float xfm[12];
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c)
                xfm[r * 4 + c] = static_cast<float>(
                    a.m.r[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]);
            xfm[r * 4 + 3] = static_cast<float>(a.t[static_cast<std::size_t>(r)] -
                                                frame[static_cast<std::size_t>(r)]);
        }
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        if (inst_object.size() <= id) inst_object.resize(id + 1, 0);
        inst_object[id] = i;
    }

    RTCScene prototype_scene(const Parts* parts) {
        auto it = prototypes.find(parts);
        if (it != prototypes.end()) return it->second;
        RTCScene s = rtcNewScene(device);
        rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
        attach_user_geometry(s, parts->part_count(), const_cast<Parts*>(parts), bounds_proto,
                             intersect_cb<Kind::kProto>, occluded_cb<Kind::kProto>);
        rtcCommitScene(s);
        prototypes[parts] = s;
        return s;
    }
};

static void on_embree_error(void* user, RTCError, const char* str) {
    static_cast<EmbreeAccel::Impl*>(user)->error = str ? str : "unknown Embree error";
}

EmbreeAccel::Impl::DirectPrim EmbreeAccel::Impl::direct_prim(std::uint32_t object,
                                                             std::uint32_t cull, bool shared,
                                                             const Placed& o,
                                                             const Transform& xf) const {
    DirectPrim d{object, cull, shared, {}};
    assert(!shared || o.cull);  // shared: one of several cull parts
    if (Capsule c; shared && o.cull->cull_capsule(cull, xf, o.widest_footprint, c))
        d.capsule = FloatCapsule::holding({c.a - frame, c.b - frame, c.r});
    return d;
}

namespace {

// AccelObjects over objects whose transforms are held by the caller.
class GivenObjects final : public AccelObjects {
public:
    explicit GivenObjects(std::span<const AccelObject> objects) : objects_(objects) {}
    std::size_t size() const override { return objects_.size(); }
    const Shape* shape(std::size_t i) const override { return objects_[i].shape; }
    Transform transform(std::size_t i) const override { return *objects_[i].xf; }
    double widest_footprint(std::size_t i) const override {
        return objects_[i].widest_footprint;
    }

private:
    std::span<const AccelObject> objects_;
};

}  // namespace

EmbreeAccel::EmbreeAccel(std::span<const AccelObject> objects, const AccelOptions& opt)
    : EmbreeAccel(GivenObjects(objects), opt) {}

EmbreeAccel::EmbreeAccel(const AccelObjects& objects, const AccelOptions& opt)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    static std::atomic<std::uint64_t> builds{0};
    m.given = &objects;
    m.build = ++builds;
    // Numbering takes a tenth of the bar, placing another, Embree's build the rest.
    ProgressBar bar("build", 1000, opt.progress, 1000);
    std::size_t cull_parts = 0;
    Impl::ShapeRoles roles;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const Shape& s = *objects.shape(i);
        roles.ask(s);
        const ShapeCull cull(s, roles.cull);
        if (Impl::enters_whole(ShapeParts(s, roles.parts), cull)) cull_parts += cull.cull_count();
    }
    m.enter_whole = cull_parts > opt.cull_part_budget;
    std::vector<Bounds3> placed_bounds;
    m.number_objects(placed_bounds);
    m.frame = Impl::frame_of(placed_bounds);
    bar.set(100);
    m.device = rtcNewDevice(nullptr);
    if (!m.device) throw std::runtime_error("Embree: cannot create a device");
    rtcSetDeviceErrorFunction(m.device, on_embree_error, &m);
    m.scene = rtcNewScene(m.device);
    rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);

    std::size_t parts = 0;
    for (const Placed& o : m.objects)
        if (Impl::part_count(o) > 1) parts += Impl::part_count(o);
    m.flatten = opt.instancing == Instancing::kNever ||
                (opt.instancing == Instancing::kAuto && parts <= opt.flatten_budget);
    for (std::uint32_t i = 0; i < m.objects.size(); ++i) {
        m.place(i, placed_bounds[i]);
        if (i % 4096 == 0) bar.set(100 + 100 * std::uint64_t{i} / m.objects.size());
    }
    placed_bounds = {};  // not held through Embree's build, the peak of memory
    // Tested one after another: in the order given, as before they were numbered in space.
    std::sort(m.unbounded.begin(), m.unbounded.end(), [&](std::uint32_t a, std::uint32_t b) {
        return m.objects[a].original < m.objects[b].original;
    });
    if (!m.direct.empty())
        m.attach_user_geometry(m.scene, m.direct.size(), &m, Impl::bounds_direct,
                               Impl::intersect_cb<Impl::Kind::kDirect>,
                               Impl::occluded_cb<Impl::Kind::kDirect>);
    if (!m.flat.empty())
        m.attach_user_geometry(m.scene, m.flat.size(), &m, Impl::bounds_flat,
                               Impl::intersect_cb<Impl::Kind::kFlat>,
                               Impl::occluded_cb<Impl::Kind::kFlat>);
    rtcSetSceneProgressMonitorFunction(
        m.scene,
        [](void* b, double done) {
            static_cast<ProgressBar*>(b)->set(200 + static_cast<std::uint64_t>(800 * done));
            return true;
        },
        &bar);
    rtcCommitScene(m.scene);
    rtcSetSceneProgressMonitorFunction(m.scene, nullptr, nullptr);
    m.direct_bounds = {};  // read only by the build
    m.given = nullptr;
    bar.finish();
    if (!m.error.empty()) throw std::runtime_error("Embree: " + m.error);
}

EmbreeAccel::~EmbreeAccel() = default;

bool EmbreeAccel::intersect(const Ray& r, double tmin, double tmax, AccelHit& hit) const {
    // Every traceable ray is finite: the second test is only for the rare huge one.
    const Impl& m = *impl_;
    const Ray framed = m.in_frame(r);
    const bool traceable = embree_can_trace(framed, tmin, tmax);
    if (!traceable && !ray_is_finite(r, tmin, tmax)) return false;
    QueryContext ctx(m, r, framed, tmin, tmax, &hit);

    if (traceable) trace_closest(m.scene, ctx, framed, tmin, tmax);

    for (const std::uint32_t i : m.unbounded) {
        const Placed& o = m.objects[i];
        const Ray local = object_ray(o, ctx);
        Crossing c;
        if (o.shape->intersect(local, tmin, ctx.found ? hit.t : tmax, c)) {
            ctx.found = true;
            hit = m.caller_hit(c.t, i, c);
        }
    }
    return ctx.found;
}

bool EmbreeAccel::intersect_layers(const Ray& r, double tmin, double tmax, std::uint32_t self,
                                   AccelHit& hit, std::vector<AccelHit>& partial,
                                   const LayerStop& stop, LastBlocker* last) const {
    LayerSink sink(partial, stop);
    const Impl& m = *impl_;
    const Ray framed = m.in_frame(r);
    const bool traceable = embree_can_trace(framed, tmin, tmax);
    if (!traceable && !ray_is_finite(r, tmin, tmax)) return false;
    QueryContext ctx(m, r, framed, tmin, tmax, &hit);
    ctx.self = m.our_number(self);
    ctx.sink = &sink;
    if (traceable && stop.shadow()) {
        if (m.blocked_by_kept(ctx, last)) {
            ctx.found = true;
        } else {
            trace_any(m.scene, ctx, framed, tmin, tmax);
            m.test_self_last(ctx);
            m.keep_blocker(ctx, last);
        }
    } else if (traceable)
        trace_closest(m.scene, ctx, framed, tmin, tmax);
    const bool blocked = ctx.found && stop.shadow();
    // Unbounded shapes answer their closest crossing: only a lattice, which has a box, has
    // several sheets (coverage/sheets.h).
    for (const std::uint32_t i : m.unbounded) {
        if (blocked) break;
        const Placed& o = m.objects[i];
        const Ray local = object_ray(o, ctx);
        Crossing c;
        const double t1 = ctx.found ? std::min(hit.t, ctx.tmax) : ctx.tmax;
        if (!o.shape->intersect(local, m.occlusion_tmin(&ctx, i, local), t1, c)) continue;
        if (c.coverage < 1.0f) {
            sink.keep(m.caller_hit(c.t, i, c));
        } else {
            ctx.found = true;
            hit = m.caller_hit(c.t, i, c);
        }
    }
    sink.finish(ctx.found, hit.t);
    return ctx.found;
}

bool EmbreeAccel::occluded(const Ray& r, double tmin, double tmax, std::uint32_t self,
                           LastBlocker* last) const {
    const Impl& m = *impl_;
    const Ray framed = m.in_frame(r);
    const bool traceable = embree_can_trace(framed, tmin, tmax);
    if (!traceable && !ray_is_finite(r, tmin, tmax)) return false;
    QueryContext ctx(m, r, framed, tmin, tmax, nullptr);
    ctx.self = m.our_number(self);
    // Only rays Embree can trace test their run's blocker first: the others meet unbounded
    // objects alone.
    if (traceable && m.blocked_by_kept(ctx, last)) return true;
    for (const std::uint32_t i : m.unbounded) {
        const Placed& o = m.objects[i];
        const Ray local = object_ray(o, ctx);
        if (o.shape->occluded(local, m.occlusion_tmin(&ctx, i, local), tmax)) {
            m.keep_blocker(ctx, last);  // nothing kept: unbounded objects are tested anyway
            return true;
        }
    }

    if (traceable) {
        trace_any(m.scene, ctx, framed, tmin, tmax);
        m.test_self_last(ctx);
    }
    m.keep_blocker(ctx, last);
    return ctx.found;
}

}  // namespace lat
