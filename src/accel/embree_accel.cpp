#include "accel/embree_accel.h"

#include <embree3/rtcore.h>

#include <cassert>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

namespace lat {
namespace {

// Per-query state. Embree hands our callbacks the RTCIntersectContext; ours extends it with
// the double-precision ray and the best hit so far (the documented way to pass query data).
struct QueryContext {
    RTCIntersectContext rtc;
    const EmbreeAccel::Impl* accel;
    Ray ray;  // world space, double
    double tmin, tmax;
    AccelHit* hit;
    bool found = false;
    std::uint32_t self = EmbreeAccel::kNoObject;  // occlusion: the object the ray leaves
    // The last object's object-space ray: consecutive parts of one object reuse it.
    std::uint32_t cached_obj = ~0u;
    Ray cached_local;
};

// A float bound that surely contains the double one, so that Embree's float traversal never
// prunes a primitive the double test would hit.
RTCBounds to_rtc_bounds(const Bounds3& b) {
    const double pad = 1e-6 * (max_component(abs(b.lo)) + max_component(abs(b.hi))) + 1e-9;
    RTCBounds r;
    r.lower_x = std::nextafter(static_cast<float>(b.lo.x - pad), -INFINITY);
    r.lower_y = std::nextafter(static_cast<float>(b.lo.y - pad), -INFINITY);
    r.lower_z = std::nextafter(static_cast<float>(b.lo.z - pad), -INFINITY);
    r.upper_x = std::nextafter(static_cast<float>(b.hi.x + pad), INFINITY);
    r.upper_y = std::nextafter(static_cast<float>(b.hi.y + pad), INFINITY);
    r.upper_z = std::nextafter(static_cast<float>(b.hi.z + pad), INFINITY);
    r.align0 = r.align1 = 0;
    return r;
}

float float_above(double t) {
    const auto f = static_cast<float>(t);
    return static_cast<double>(f) > t ? f : std::nextafter(f, INFINITY);
}

void set_rtc_ray(RTCRay& ray, const Ray& r, double tmin, double tmax) {
    ray.org_x = static_cast<float>(r.o.x);
    ray.org_y = static_cast<float>(r.o.y);
    ray.org_z = static_cast<float>(r.o.z);
    ray.dir_x = static_cast<float>(r.d.x);
    ray.dir_y = static_cast<float>(r.d.y);
    ray.dir_z = static_cast<float>(r.d.z);
    // Embree prunes in float: widen the range a little so that it never cuts a double hit.
    ray.tnear = std::max(0.0f, static_cast<float>(tmin) * 0.5f);
    ray.tfar = std::isfinite(tmax) ? float_above(tmax) : INFINITY;
    ray.time = 0;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
}

}  // namespace

struct EmbreeAccel::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<AccelObject> objects;
    std::vector<std::uint32_t> direct;       // primID -> object, for the top-level user geometry
    std::vector<std::uint32_t> unbounded;    // objects tested outside Embree
    std::vector<std::uint32_t> inst_object;  // top-level geomID -> object, for instances
    struct FlatPrim {
        std::uint32_t object, part;
    };
    std::vector<FlatPrim> flat;  // parts of multi-part objects placed directly in world space
    bool flatten = false;
    struct Prototype {
        const Shape* shape;
        RTCScene scene;
    };
    std::map<const Shape*, Prototype> prototypes;
    std::string error;

    ~Impl() {
        for (auto& [s, p] : prototypes) rtcReleaseScene(p.scene);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    // The start of an occlusion test against object obj (see EmbreeAccel::occluded).
    double occlusion_tmin(const QueryContext* ctx, std::uint32_t obj, const Ray& local) const {
        if (obj != ctx->self) return ctx->tmin;
        const double tol = objects[obj].shape->surface_tolerance();
        return tol > 0 ? ctx->tmin + tol / length(local.d) : ctx->tmin;
    }

    const Ray& local_ray(QueryContext* ctx, std::uint32_t obj) const {
        if (ctx->cached_obj != obj) {
            ctx->cached_obj = obj;
            ctx->cached_local = objects[obj].xf->inverse_ray(ctx->ray);
        }
        return ctx->cached_local;
    }

    void record(QueryContext* ctx, RTCRayHit* rh, std::uint32_t obj, const Crossing& c,
                unsigned geom, unsigned prim, unsigned inst) const {
        ctx->found = true;
        *ctx->hit = {c.t, obj, c};
        rh->ray.tfar = float_above(c.t);
        rh->hit.geomID = geom;
        rh->hit.primID = prim;
        rh->hit.instID[0] = inst;
        rh->hit.Ng_x = 0;
        rh->hit.Ng_y = 0;
        rh->hit.Ng_z = 1;
        rh->hit.u = rh->hit.v = 0;
    }

    static void direct_intersect(const RTCIntersectFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const std::uint32_t obj = self->direct[args->primID];
        const AccelObject& o = self->objects[obj];
        const Ray local = o.xf->is_identity() ? ctx->ray : o.xf->inverse_ray(ctx->ray);
        const double tmax = ctx->found ? ctx->hit->t : ctx->tmax;
        Crossing c;
        if (o.shape->intersect(local, ctx->tmin, tmax, c))
            self->record(ctx, reinterpret_cast<RTCRayHit*>(args->rayhit), obj, c, args->geomID,
                         args->primID, RTC_INVALID_GEOMETRY_ID);
    }

    static void direct_occluded(const RTCOccludedFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const std::uint32_t obj = self->direct[args->primID];
        const AccelObject& o = self->objects[obj];
        const Ray local = o.xf->is_identity() ? ctx->ray : o.xf->inverse_ray(ctx->ray);
        if (o.shape->occluded(local, self->occlusion_tmin(ctx, obj, local), ctx->tmax)) {
            ctx->found = true;
            reinterpret_cast<RTCRay*>(args->ray)->tfar = -INFINITY;
        }
    }

    static void proto_intersect(const RTCIntersectFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const unsigned inst = args->context->instID[0];
        const std::uint32_t obj = self->inst_object[inst];
        const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
        const Ray& local = self->local_ray(ctx, obj);
        const double tmax = ctx->found ? ctx->hit->t : ctx->tmax;
        Crossing c;
        if (shape->intersect_primitive(args->primID, local, ctx->tmin, tmax, c))
            self->record(ctx, reinterpret_cast<RTCRayHit*>(args->rayhit), obj, c, args->geomID,
                         args->primID, inst);
    }

    static void proto_occluded(const RTCOccludedFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const unsigned inst = args->context->instID[0];
        const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
        const std::uint32_t obj = self->inst_object[inst];
        const Ray& local = self->local_ray(ctx, obj);
        if (shape->occluded_primitive(args->primID, local, self->occlusion_tmin(ctx, obj, local),
                                      ctx->tmax)) {
            ctx->found = true;
            reinterpret_cast<RTCRay*>(args->ray)->tfar = -INFINITY;
        }
    }

    static void flat_intersect(const RTCIntersectFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const FlatPrim fp = self->flat[args->primID];
        const Ray& local = self->local_ray(ctx, fp.object);
        const double tmax = ctx->found ? ctx->hit->t : ctx->tmax;
        Crossing c;
        if (self->objects[fp.object].shape->intersect_primitive(fp.part, local, ctx->tmin, tmax, c))
            self->record(ctx, reinterpret_cast<RTCRayHit*>(args->rayhit), fp.object, c,
                         args->geomID, args->primID, RTC_INVALID_GEOMETRY_ID);
    }

    static void flat_occluded(const RTCOccludedFunctionNArguments* args) {
        if (!args->valid[0]) return;
        auto* ctx = reinterpret_cast<QueryContext*>(args->context);
        const Impl* self = ctx->accel;
        const FlatPrim fp = self->flat[args->primID];
        const Ray& local = self->local_ray(ctx, fp.object);
        if (self->objects[fp.object].shape->occluded_primitive(
                fp.part, local, self->occlusion_tmin(ctx, fp.object, local), ctx->tmax)) {
            ctx->found = true;
            reinterpret_cast<RTCRay*>(args->ray)->tfar = -INFINITY;
        }
    }

    static void bounds_flat(const RTCBoundsFunctionArguments* args) {
        const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
        const FlatPrim fp = self->flat[args->primID];
        const AccelObject& o = self->objects[fp.object];
        *args->bounds_o = to_rtc_bounds(o.shape->primitive_bounds(fp.part, *o.xf));
    }

    static void bounds_direct(const RTCBoundsFunctionArguments* args) {
        const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
        const AccelObject& o = self->objects[self->direct[args->primID]];
        *args->bounds_o = to_rtc_bounds(o.xf->bounds(o.shape->bounds()));
    }

    static void bounds_proto(const RTCBoundsFunctionArguments* args) {
        const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
        *args->bounds_o = to_rtc_bounds(shape->primitive_bounds(args->primID));
    }

    // One user geometry of n primitives with these callbacks, attached to scene s.
    void attach_user_geometry(RTCScene s, std::size_t n, void* user, RTCBoundsFunction bounds,
                              RTCIntersectFunctionN intersect, RTCOccludedFunctionN occluded) const {
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

    RTCScene prototype_scene(const Shape* shape) {
        auto it = prototypes.find(shape);
        if (it != prototypes.end()) return it->second.scene;
        RTCScene s = rtcNewScene(device);
        rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
        attach_user_geometry(s, shape->primitive_count(), const_cast<Shape*>(shape), bounds_proto,
                             proto_intersect, proto_occluded);
        rtcCommitScene(s);
        prototypes[shape] = {shape, s};
        return s;
    }
};

static void on_embree_error(void* user, RTCError, const char* str) {
    static_cast<EmbreeAccel::Impl*>(user)->error = str ? str : "unknown Embree error";
}

EmbreeAccel::EmbreeAccel(std::span<const AccelObject> objects, const AccelOptions& opt)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.objects.assign(objects.begin(), objects.end());
    m.device = rtcNewDevice(nullptr);
    if (!m.device) throw std::runtime_error("Embree: cannot create a device");
    rtcSetDeviceErrorFunction(m.device, on_embree_error, &m);
    m.scene = rtcNewScene(m.device);
    rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);

    std::size_t parts = 0;
    for (const AccelObject& o : m.objects)
        if (o.shape->primitive_count() > 1) parts += o.shape->primitive_count();
    m.flatten = opt.instancing == Instancing::kNever ||
                (opt.instancing == Instancing::kAuto && parts <= opt.flatten_budget);

    for (std::uint32_t i = 0; i < m.objects.size(); ++i) {
        const AccelObject& o = m.objects[i];
        const Bounds3 wb = o.xf->bounds(o.shape->bounds());
        if (wb.empty()) continue;
        if (!wb.finite()) {
            m.unbounded.push_back(i);
        } else if (o.shape->primitive_count() > 1 && m.flatten) {
            for (std::uint32_t p = 0; p < o.shape->primitive_count(); ++p) m.flat.push_back({i, p});
        } else if (o.shape->primitive_count() > 1) {
            RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, m.prototype_scene(o.shape));
            const Affine& a = o.xf->forward();
            float xfm[12];
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c)
                    xfm[r * 4 + c] = static_cast<float>(a.m.r[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]);
                xfm[r * 4 + 3] = static_cast<float>(a.t[static_cast<std::size_t>(r)]);
            }
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
            rtcCommitGeometry(g);
            const unsigned id = rtcAttachGeometry(m.scene, g);
            rtcReleaseGeometry(g);
            if (m.inst_object.size() <= id) m.inst_object.resize(id + 1, 0);
            m.inst_object[id] = i;
        } else {
            m.direct.push_back(i);
        }
    }
    if (!m.direct.empty())
        m.attach_user_geometry(m.scene, m.direct.size(), &m, Impl::bounds_direct,
                               Impl::direct_intersect, Impl::direct_occluded);
    if (!m.flat.empty())
        m.attach_user_geometry(m.scene, m.flat.size(), &m, Impl::bounds_flat, Impl::flat_intersect,
                               Impl::flat_occluded);
    rtcCommitScene(m.scene);
    if (!m.error.empty()) throw std::runtime_error("Embree: " + m.error);
}

EmbreeAccel::~EmbreeAccel() = default;

bool EmbreeAccel::flattened() const { return impl_->flatten; }

bool EmbreeAccel::intersect(const Ray& r, double tmin, double tmax, AccelHit& hit) const {
    const Impl& m = *impl_;
    QueryContext ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.accel = &m;
    ctx.ray = r;
    ctx.tmin = tmin;
    ctx.tmax = tmax;
    ctx.hit = &hit;

    alignas(16) RTCRayHit rh;
    set_rtc_ray(rh.ray, r, tmin, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m.scene, &ctx.rtc, &rh);

    for (const std::uint32_t i : m.unbounded) {
        const AccelObject& o = m.objects[i];
        const Ray local = o.xf->is_identity() ? r : o.xf->inverse_ray(r);
        Crossing c;
        if (o.shape->intersect(local, tmin, ctx.found ? hit.t : tmax, c)) {
            ctx.found = true;
            hit = {c.t, i, c};
        }
    }
    return ctx.found;
}

bool EmbreeAccel::occluded(const Ray& r, double tmin, double tmax, std::uint32_t self) const {
    const Impl& m = *impl_;
    AccelHit unused;
    QueryContext ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.accel = &m;
    ctx.ray = r;
    ctx.tmin = tmin;
    ctx.tmax = tmax;
    ctx.hit = &unused;
    ctx.self = self;
    for (const std::uint32_t i : m.unbounded) {
        const AccelObject& o = m.objects[i];
        const Ray local = o.xf->is_identity() ? r : o.xf->inverse_ray(r);
        if (o.shape->occluded(local, m.occlusion_tmin(&ctx, i, local), tmax)) return true;
    }

    alignas(16) RTCRay ray;
    set_rtc_ray(ray, r, tmin, tmax);
    rtcOccluded1(m.scene, &ctx.rtc, &ray);
    return ctx.found;
}

}  // namespace lat
