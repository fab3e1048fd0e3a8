// embree_tracer SCENE.json -o OUT.png [--threads N] [--geometry user|native] [--packets] [--rounds R]
// An independent Embree tracer for "lattice-reference/1" scenes (hairs of balls and cylinders,
// spheres, half-spaces): the yardstick of "exact mode at most the time of an
// independent Embree tracer on the same machine" (bench/embree_tracer.py, docs/complexity.md).
// It reads the scene with the reference tracer's parser (tests/reference) and shares no code
// with src/ but the PNG writer: geometry, Embree set-up, traversal and shading are its own,
// written as a user of Embree would write them.
//   --geometry user:   balls and flat-ended cylinders as Embree user geometry, intersected in
//                      double on the world ray mapped by each instance (the reference's rules,
//                      in double instead of long double);
//   --geometry native: Embree's own float primitives (RTC_GEOMETRY_TYPE_SPHERE_POINT, capped
//                      cones RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE) and Embree's float distances.
// Half-spaces are tested in double, outside Embree, in both. One ray a pixel through its centre,
// Phong shading with hard shadows as the reference README defines them. Prints one JSON line:
// build and render times (rendering only, median of --rounds).
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/image.h"
#include "reference_tracer.h"

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct V {
    double x = 0, y = 0, z = 0;
};
V operator+(V a, V b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V operator-(V a, V b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V operator*(double s, V a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V cross(V a, V b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
V normalize(V a) { return (1 / std::sqrt(dot(a, a))) * a; }
V from(const reftrace::Vec& v) { return {double(v.x), double(v.y), double(v.z)}; }

using M3 = double[3][3];
V mul(const M3& m, V v) {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}
V mul_transposed(const M3& m, V v) {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
}

// Where a ray is inside a convex solid, and the outward normal where it enters.
struct Span {
    double t0 = kInf, t1 = -kInf;
    V n;
    bool empty() const { return !(t0 <= t1); }
};

// Solutions of a t^2 + 2 b t + c <= 0, a > 0, without cancellation.
bool quadratic_span(double a, double b, double c, double& t0, double& t1) {
    const double disc = b * b - a * c;
    if (disc < 0) return false;
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    if (q == 0) {
        t0 = t1 = 0;
        return true;
    }
    t0 = q / a, t1 = c / q;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

struct Ball {
    V c;
    double r;
};
struct Cylinder {
    V a, axis;
    double length, r;
};

Span ball_span(V o, V d, const Ball& b) {
    Span s;
    const V w = o - b.c;
    if (quadratic_span(dot(d, d), dot(w, d), dot(w, w) - b.r * b.r, s.t0, s.t1)) s.n = o + s.t0 * d - b.c;
    return s;
}

Span cylinder_span(V o, V d, const Cylinder& c) {
    Span s;
    const V w = o - c.a;
    const double wa = dot(w, c.axis), da = dot(d, c.axis);
    double s0 = -kInf, s1 = kInf;  // between the end planes
    if (da == 0) {
        if (wa < 0 || wa > c.length) return s;
    } else {
        s0 = -wa / da, s1 = (c.length - wa) / da;
        if (s0 > s1) std::swap(s0, s1);
    }
    const V wp = w - wa * c.axis, dp = d - da * c.axis;  // across the axis
    double l0 = -kInf, l1 = kInf;
    const double a = dot(dp, dp);
    if (a == 0) {
        if (dot(wp, wp) > c.r * c.r) return s;
    } else if (!quadratic_span(a, dot(wp, dp), dot(wp, wp) - c.r * c.r, l0, l1)) {
        return s;
    }
    s.t0 = std::max(s0, l0), s.t1 = std::min(s1, l1);
    if (!s.empty()) s.n = l0 >= s0 ? wp + l0 * dp : (da > 0 ? -1 * c.axis : c.axis);
    return s;
}

// A primitive: its parts (balls first, then cylinders) and its Embree scene.
struct Proto {
    std::vector<Ball> balls;
    std::vector<Cylinder> cylinders;
    RTCScene scene = nullptr;
    float pad = 0;  // how far its parts' boxes are widened (pad_for_instances)
    Span span(V o, V d, unsigned part) const {
        return part < balls.size() ? ball_span(o, d, balls[part]) : cylinder_span(o, d, cylinders[part - balls.size()]);
    }
};

struct Object {
    int material = 0;
    const Proto* proto = nullptr;  // an instance's; else a sphere (ball) or a half-space
    Ball ball{};
    V point, normal;                // half-space: dot(x - point, normal) <= 0
    M3 minv{};                      // instance: local = minv (world - t)
    V t;
};

struct World;

// Rays traced together (--packets): rtcIntersect8 / rtcOccluded8; a single ray is lane 0.
constexpr int kLanes = 8;

// One query of up to kLanes rays: Embree's context first (Embree hands it back to the
// callbacks), then each lane's world ray in double and what it found.
struct Query {
    RTCIntersectContext rtc;
    const World* world;
    V o[kLanes], d[kLanes];
    double tmin[kLanes], tmax[kLanes];  // closest: (0, best so far); occlusion: the segment
    int object[kLanes];
    V n[kLanes];  // the hit's outward normal, world
};

struct World {
    reftrace::Scene ref;
    std::vector<Proto> protos;
    std::vector<Object> objects;
    std::vector<unsigned> instance_object;  // top-level geometry ID of an instance -> object
    std::vector<unsigned> sphere_object;    // primitive ID in the spheres' geometry -> object
    std::vector<unsigned> planes;           // objects tested outside Embree
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    bool native = false;
    ~World() {
        for (Proto& p : protos)
            if (p.scene) rtcReleaseScene(p.scene);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

// The float above t's nearest float, from the bits (t finite and positive here; libm's nextafterf
// cost this tracer 5 % of its instructions).
float float_up(double t) {
    const float f = static_cast<float>(t);
    return std::isinf(f) ? f : std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) + 1);
}
float float_down(double t) {
    const float f = static_cast<float>(t);
    return f > 0 ? std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) - 1) : 0.0f;
}

// The object a primitive belongs to: an instance's, else one of the top-level spheres.
unsigned object_hit(const World& w, unsigned inst, unsigned prim) {
    return inst != RTC_INVALID_GEOMETRY_ID ? w.instance_object[inst] : w.sphere_object[prim];
}

// The callbacks of user geometry: an instance's parts (mapped by its transform, in double) or a
// top-level sphere.

Span user_span(const Query& q, int k, const Object& obj, unsigned prim, V& n_world) {
    if (!obj.proto) {
        const Span s = ball_span(q.o[k], q.d[k], obj.ball);
        n_world = s.n;
        return s;
    }
    const V o = mul(obj.minv, q.o[k] - obj.t), d = mul(obj.minv, q.d[k]);
    const Span s = obj.proto->span(o, d, prim);
    n_world = mul_transposed(obj.minv, s.n);
    return s;
}

// Embree calls these with N rays (1 for rtcIntersect1, up to 8 for rtcIntersect8); ray k of the
// call is the query's lane RTCRayN_id (init_ray sets it), whatever order Embree passes them in.
void user_intersect(const RTCIntersectFunctionNArguments* a) {
    auto* q = reinterpret_cast<Query*>(a->context);
    const unsigned i = object_hit(*q->world, a->context->instID[0], a->primID);
    RTCRayN* ray = RTCRayHitN_RayN(a->rayhit, a->N);
    for (unsigned k = 0; k < a->N; ++k) {
        if (!a->valid[k]) continue;
        const int lane = int(RTCRayN_id(ray, a->N, k));
        V n;
        const Span s = user_span(*q, lane, q->world->objects[i], a->primID, n);
        if (s.empty() || !(s.t0 > 0) || !(s.t0 < q->tmax[lane])) continue;
        q->tmax[lane] = s.t0, q->object[lane] = int(i), q->n[lane] = n;
        RTCRayN_tfar(ray, a->N, k) = float_up(s.t0);
        RTCHitN_geomID(RTCRayHitN_HitN(a->rayhit, a->N), a->N, k) = a->geomID;
    }
}

void user_occluded(const RTCOccludedFunctionNArguments* a) {
    auto* q = reinterpret_cast<Query*>(a->context);
    const unsigned i = object_hit(*q->world, a->context->instID[0], a->primID);
    for (unsigned k = 0; k < a->N; ++k) {
        if (!a->valid[k]) continue;
        const int lane = int(RTCRayN_id(a->ray, a->N, k));
        V n;
        const Span s = user_span(*q, lane, q->world->objects[i], a->primID, n);
        if (!s.empty() && s.t1 > q->tmin[lane] && s.t0 < q->tmax[lane]) RTCRayN_tfar(a->ray, a->N, k) = -kInf;
    }
}

// Bounds of a user primitive widened by `extra` and by 1e-4 of its own largest coordinate (plus 1),
// so that float boxes never cull what the double test would find.
void pad_box(RTCBounds& b, float extra) {
    const float pad = extra + 1e-4f * (1 + std::max({std::fabs(b.lower_x), std::fabs(b.upper_x), std::fabs(b.lower_y),
                                                      std::fabs(b.upper_y), std::fabs(b.lower_z), std::fabs(b.upper_z)}));
    b.lower_x -= pad, b.lower_y -= pad, b.lower_z -= pad;
    b.upper_x += pad, b.upper_y += pad, b.upper_z += pad;
}

RTCBounds ball_bounds(const Ball& b) {
    return {float(b.c.x - b.r), float(b.c.y - b.r), float(b.c.z - b.r), 0,
            float(b.c.x + b.r), float(b.c.y + b.r), float(b.c.z + b.r), 0};
}

void proto_bounds(const RTCBoundsFunctionArguments* a) {
    const auto* p = static_cast<const Proto*>(a->geometryUserPtr);
    RTCBounds b;
    if (a->primID < p->balls.size()) {
        b = ball_bounds(p->balls[a->primID]);
    } else {
        const Cylinder& c = p->cylinders[a->primID - p->balls.size()];
        const V e = c.a + c.length * c.axis;
        b = {float(std::min(c.a.x, e.x) - c.r), float(std::min(c.a.y, e.y) - c.r), float(std::min(c.a.z, e.z) - c.r), 0,
             float(std::max(c.a.x, e.x) + c.r), float(std::max(c.a.y, e.y) + c.r), float(std::max(c.a.z, e.z) + c.r), 0};
    }
    pad_box(b, p->pad);
    *a->bounds_o = b;
}

void sphere_bounds(const RTCBoundsFunctionArguments* a) {
    const auto* w = static_cast<const World*>(a->geometryUserPtr);
    RTCBounds b = ball_bounds(w->objects[w->sphere_object[a->primID]].ball);
    pad_box(b, 0);
    *a->bounds_o = b;
}

RTCGeometry user_geometry(RTCDevice dev, unsigned count, void* ptr, RTCBoundsFunction bounds) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, count);
    rtcSetGeometryUserData(g, ptr);
    rtcSetGeometryBoundsFunction(g, bounds, ptr);
    rtcSetGeometryIntersectFunction(g, user_intersect);
    rtcSetGeometryOccludedFunction(g, user_occluded);
    return g;
}

// Balls as Embree's points with a radius, one primitive each.
RTCGeometry native_points(RTCDevice dev, const std::vector<Ball>& balls) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), balls.size()));
    for (const Ball& b : balls) *v++ = float(b.c.x), *v++ = float(b.c.y), *v++ = float(b.c.z), *v++ = float(b.r);
    return g;
}

// Embree's own primitives: balls as points with a radius, cylinders as capped cones.
void attach_native(RTCDevice dev, RTCScene s, const Proto& p) {
    if (!p.balls.empty()) {
        RTCGeometry g = native_points(dev, p.balls);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s, g, 0);
        rtcReleaseGeometry(g);
    }
    if (!p.cylinders.empty()) {
        const std::size_t n = p.cylinders.size();
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE);
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * n));
        auto* idx = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), n));
        for (std::size_t k = 0; k < n; ++k) {
            const Cylinder& c = p.cylinders[k];
            for (const V e : {c.a, c.a + c.length * c.axis})
                *v++ = float(e.x), *v++ = float(e.y), *v++ = float(e.z), *v++ = float(c.r);
            idx[k] = static_cast<unsigned>(2 * k);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s, g, 1);
        rtcReleaseGeometry(g);
    }
}

// Embree maps a world ray into an instance's space in float: the mapped origin is off by a few
// float roundings of |minv| (|origin| + |t|). Each prototype's boxes are widened by 1e-5 of that
// (about 100 roundings) for its most magnifying instance, |origin| taken as at most the eye's or
// an instance's distance from 0, so that a small instance far from the eye is not culled where
// the double test hits. A shadow ray from a floor point farther out than that has less margin
// (the images are still identical to exact mode's on the bench's scenes).
void pad_for_instances(World& w) {
    double reach = 1 + std::max({std::fabs(w.ref.camera.eye.x), std::fabs(w.ref.camera.eye.y),
                                 std::fabs(w.ref.camera.eye.z)});
    for (const reftrace::Object& ro : w.ref.objects)
        if (ro.kind == reftrace::Kind::instance)
            reach = std::max({reach, 1 + std::fabs(double(ro.t.x)), 1 + std::fabs(double(ro.t.y)),
                              1 + std::fabs(double(ro.t.z))});
    for (const reftrace::Object& ro : w.ref.objects) {
        if (ro.kind != reftrace::Kind::instance) continue;
        double norm = 0;  // the inverse's largest row sum
        for (int r = 0; r < 3; ++r)
            norm = std::max(norm, std::fabs(double(ro.minv[r][0])) + std::fabs(double(ro.minv[r][1])) +
                                      std::fabs(double(ro.minv[r][2])));
        Proto& p = w.protos[std::size_t(ro.primitive)];
        p.pad = std::max(p.pad, float(1e-5 * norm * 2 * reach));
    }
}

void build_protos(World& w) {
    for (const reftrace::Primitive& rp : w.ref.primitives) {
        Proto p;
        for (const auto& b : rp.balls) p.balls.push_back({from(b.c), double(b.r)});
        for (const auto& c : rp.cylinders) p.cylinders.push_back({from(c.a), from(c.axis), double(c.length), double(c.r)});
        w.protos.push_back(std::move(p));
    }
    pad_for_instances(w);
    for (Proto& p : w.protos) {  // stable addresses from here on
        p.scene = rtcNewScene(w.device);
        rtcSetSceneBuildQuality(p.scene, RTC_BUILD_QUALITY_HIGH);
        if (w.native) {
            attach_native(w.device, p.scene, p);
        } else {
            RTCGeometry g = user_geometry(w.device, unsigned(p.balls.size() + p.cylinders.size()), &p, proto_bounds);
            rtcCommitGeometry(g);
            rtcAttachGeometry(p.scene, g);
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(p.scene);
    }
}

void attach_instance(World& w, unsigned i, const reftrace::Object& ro) {
    Object& o = w.objects[i];
    o.proto = &w.protos[std::size_t(ro.primitive)];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) o.minv[r][c] = double(ro.minv[r][c]);
    o.t = from(ro.t);
    RTCGeometry g = rtcNewGeometry(w.device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, o.proto->scene);
    const float xfm[12] = {float(ro.m[0][0]), float(ro.m[0][1]), float(ro.m[0][2]), float(ro.t.x),
                           float(ro.m[1][0]), float(ro.m[1][1]), float(ro.m[1][2]), float(ro.t.y),
                           float(ro.m[2][0]), float(ro.m[2][1]), float(ro.m[2][2]), float(ro.t.z)};
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(w.scene, g);
    if (w.instance_object.size() <= id) w.instance_object.resize(id + 1);
    w.instance_object[id] = i;
    rtcReleaseGeometry(g);
}

// The spheres: one geometry, user or Embree points, a primitive each.
void attach_spheres(World& w) {
    const std::vector<unsigned>& spheres = w.sphere_object;
    if (spheres.empty()) return;
    RTCGeometry g;
    if (w.native) {
        std::vector<Ball> balls;
        for (const unsigned i : spheres) balls.push_back(w.objects[i].ball);
        g = native_points(w.device, balls);
    } else {
        g = user_geometry(w.device, unsigned(spheres.size()), &w, sphere_bounds);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(w.scene, g);
    rtcReleaseGeometry(g);
}

void build_world(World& w) {
    w.objects.resize(w.ref.objects.size());
    build_protos(w);
    w.scene = rtcNewScene(w.device);
    rtcSetSceneBuildQuality(w.scene, RTC_BUILD_QUALITY_HIGH);
    for (unsigned i = 0; i < w.ref.objects.size(); ++i) {
        const reftrace::Object& ro = w.ref.objects[i];
        Object& o = w.objects[i];
        o.material = ro.material;
        if (ro.kind == reftrace::Kind::instance) {
            attach_instance(w, i, ro);
        } else if (ro.kind == reftrace::Kind::sphere) {
            o.ball = {from(ro.ball.c), double(ro.ball.r)};
            w.sphere_object.push_back(i);
        } else {
            o.point = from(ro.point), o.normal = from(ro.normal);
            w.planes.push_back(i);
        }
    }
    attach_spheres(w);
    rtcCommitScene(w.scene);
}

// How far shadow rays start from the surface (world units). The reference's 1e-9 is for long
// double: in double, a hit point on a thin strand under an instance's transform lies inside its
// own part by up to ~1e-10 of the world ray's length, and a ray leaving it at a slant met that part
// again (tuft2000: 0.8 % of the pixels lost a light). So 1e-7 of the point's largest coordinate
// (plus 1), far above double rounding and far below any part. This is exact mode's own rule
// (src/render/core/shading.cpp's shadow_epsilon), so the images' identity with exact mode is partly by
// construction: it checks the geometry and shading, not the choice of offset. Native hits'
// distances are float, so 1e-3 there.
double shadow_offset(const World& w, V p) {
    if (w.native) return 1e-3;
    return 1e-7 * (1 + std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}));
}

struct Hit {
    double t = kInf;
    int object = -1;
    V n;  // outward, world, any length
};

Query query(const World& w) {
    Query q;
    rtcInitIntersectContext(&q.rtc);
    q.world = &w;
    return q;
}

void set_lane(Query& q, int k, V o, V d, double tmin, double tmax) {
    q.o[k] = o, q.d[k] = d, q.tmin[k] = tmin, q.tmax[k] = tmax, q.object[k] = -1;
}

// The float ray Embree traverses with: a range that holds the double one.
void init_ray(RTCRay& r, V o, V d, double tmin, double tmax) {
    r.org_x = float(o.x), r.org_y = float(o.y), r.org_z = float(o.z);
    r.dir_x = float(d.x), r.dir_y = float(d.y), r.dir_z = float(d.z);
    r.tnear = float_down(tmin);
    r.tfar = std::isfinite(tmax) ? float_up(tmax) : INFINITY;
    r.time = 0, r.mask = ~0u, r.id = 0, r.flags = 0;
}
void init_ray(RTCRay8& r, int k, V o, V d, double tmin, double tmax) {
    RTCRay one;
    init_ray(one, o, d, tmin, tmax);
    r.org_x[k] = one.org_x, r.org_y[k] = one.org_y, r.org_z[k] = one.org_z;
    r.dir_x[k] = one.dir_x, r.dir_y[k] = one.dir_y, r.dir_z[k] = one.dir_z;
    r.tnear[k] = one.tnear, r.tfar[k] = one.tfar;
    r.time[k] = 0, r.mask[k] = ~0u, r.id[k] = unsigned(k), r.flags[k] = 0;  // id: the query's lane
}

// A native hit: Embree's float distance and its normal, in the instance's space for instances.
Hit native_hit(const World& w, float t, unsigned inst, unsigned prim, V ng) {
    const unsigned i = object_hit(w, inst, prim);
    const Object& o = w.objects[i];
    return {t, int(i), o.proto ? mul_transposed(o.minv, ng) : ng};
}

// Lane k's hit: the user callbacks' double one, or Embree's native one (geom invalid: none).
Hit lane_hit(const World& w, const Query& q, int k, unsigned geom, float t, unsigned inst, unsigned prim, V ng) {
    if (!w.native) return q.object[k] >= 0 ? Hit{q.tmax[k], q.object[k], q.n[k]} : Hit{};
    return geom != RTC_INVALID_GEOMETRY_ID ? native_hit(w, t, inst, prim, ng) : Hit{};
}

// The half-spaces, tested in double after Embree.
void add_planes(const World& w, V o, V d, Hit& h) {
    for (const unsigned i : w.planes) {
        const Object& p = w.objects[i];
        const double dn = dot(d, p.normal), t = -dot(o - p.point, p.normal) / dn;
        if (dn < 0 && t > 0 && t < h.t) h = {t, int(i), p.normal};
    }
}
bool planes_block(const World& w, V o, V d, double tmin, double tmax) {
    for (const unsigned i : w.planes) {
        const Object& p = w.objects[i];
        const double dn = dot(d, p.normal), wn = dot(o - p.point, p.normal);
        if (dn == 0 ? wn <= 0 : dn < 0 ? -wn / dn < tmax : -wn / dn > tmin) return true;
    }
    return false;
}

Hit closest(const World& w, V o, V d) {
    Query q = query(w);
    set_lane(q, 0, o, d, 0, kInf);
    RTCRayHit rh;
    init_ray(rh.ray, o, d, 0, kInf);
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(w.scene, &q.rtc, &rh);
    Hit h = lane_hit(w, q, 0, rh.hit.geomID, rh.ray.tfar, rh.hit.instID[0], rh.hit.primID,
                     {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
    add_planes(w, o, d, h);
    return h;
}

// Is there solid on the segment o + t d, tmin < t < tmax? (d of unit length: Embree's float
// curves over-report occlusion along a direction 600 units long.)
bool blocked(const World& w, V o, V d, double tmin, double tmax) {
    if (planes_block(w, o, d, tmin, tmax)) return true;
    Query q = query(w);
    set_lane(q, 0, o, d, tmin, tmax);
    RTCRay r;
    init_ray(r, o, d, tmin, tmax);
    rtcOccluded1(w.scene, &q.rtc, &r);
    return r.tfar < 0;
}

// The reference camera: pixel (i, j)'s ray through its centre, the frame worked out once.
struct Camera {
    V eye, w, u, v;
    double h, aspect;
    int width, height;
    explicit Camera(const reftrace::Camera& c)
        : eye(from(c.eye)), w(normalize(from(c.look_at) - eye)), u(normalize(cross(w, from(c.up)))),
          v(cross(u, w)), h(std::tan(double(c.fov_y_deg) * std::numbers::pi / 360)),
          aspect(double(c.width) / c.height), width(c.width), height(c.height) {}
    V ray(int i, int j) const {
        const double x = (2 * (i + 0.5) / width - 1) * aspect * h, y = (1 - 2 * (j + 0.5) / height) * h;
        return normalize(w + x * u + y * v);
    }
};

// A shadow ray from p: unit direction, start and end.
struct ShadowRay {
    V l;
    double tmin, tmax;
};
ShadowRay shadow_ray(const World& w, V p, const reftrace::Light& light) {
    const V to = from(light.position) - p;
    const double dist = std::sqrt(dot(to, to));
    return {(1 / dist) * to, shadow_offset(w, p), dist};
}

// Phong with hard shadows, as the reference README defines it; seen(k, shadow ray): whether light
// k reaches the hit (its shadow ray unblocked, or no shadows).
template <class Seen>
V phong(const World& w, const Hit& h, V o, V d, Seen&& seen) {
    const reftrace::Scene& s = w.ref;
    const V p = o + h.t * d, view = -1 * d;
    V n = normalize(h.n);
    if (dot(n, view) < 0) n = -1 * n;
    const reftrace::Material& m = s.materials[std::size_t(w.objects[std::size_t(h.object)].material)];
    const V col = from(m.color), amb = from(s.ambient);
    const double ka = double(m.ka), kd = double(m.kd), ks = double(m.ks), shine = double(m.shininess);
    V c{ka * col.x * amb.x, ka * col.y * amb.y, ka * col.z * amb.z};
    for (std::size_t k = 0; k < s.lights.size(); ++k) {
        const ShadowRay r = shadow_ray(w, p, s.lights[k]);
        if (!seen(k, r)) continue;
        const V l = r.l;
        const double nl = dot(n, l);
        const double spec = ks * std::pow(std::max(0.0, dot(2 * nl * n - l, view)), shine);
        const double diff = kd * std::max(0.0, nl);
        const V in = from(s.lights[k].intensity);
        c = c + V{in.x * (diff * col.x + spec), in.y * (diff * col.y + spec), in.z * (diff * col.z + spec)};
    }
    return c;
}

V shade(const World& w, V o, V d) {
    const Hit h = closest(w, o, d);
    if (h.object < 0) return from(w.ref.background);
    const V p = o + h.t * d;
    return phong(w, h, o, d, [&](std::size_t, const ShadowRay& r) {
        return !w.ref.shadows || !blocked(w, p, r.l, r.tmin, r.tmax);
    });
}

// count (at most kLanes) camera rays from o along d[], as one packet each way: their hits.
void closest8(const World& w, V o, const V* d, int count, Hit* out) {
    Query q = query(w);
    RTCRayHit8 rh;
    alignas(32) int valid[kLanes];  // Embree reads the mask as one 32-byte vector
    for (int k = 0; k < kLanes; ++k) {
        valid[k] = k < count ? -1 : 0;
        const V dk = k < count ? d[k] : d[0];
        set_lane(q, k, o, dk, 0, kInf);
        init_ray(rh.ray, k, o, dk, 0, kInf);
        rh.hit.geomID[k] = rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, w.scene, &q.rtc, &rh);
    for (int k = 0; k < count; ++k) {
        out[k] = lane_hit(w, q, k, rh.hit.geomID[k], rh.ray.tfar[k], rh.hit.instID[0][k], rh.hit.primID[k],
                          {rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]});
        add_planes(w, o, d[k], out[k]);
    }
}

// Whether light `light` reaches each hit of the packet (seen[k]), its shadow rays as one packet.
void seen8(const World& w, V o, const V* d, const Hit* h, int count, std::size_t light, bool* seen) {
    Query q = query(w);
    RTCRay8 r;
    alignas(32) int valid[kLanes];  // Embree reads the mask as one 32-byte vector
    bool any = false;
    for (int k = 0; k < kLanes; ++k) {
        valid[k] = 0;
        seen[k] = true;
        set_lane(q, k, o, d[0], 0, 0);
        init_ray(r, k, o, d[0], 0, 0);
        if (k >= count || h[k].object < 0) continue;
        const V p = o + h[k].t * d[k];
        const ShadowRay s = shadow_ray(w, p, w.ref.lights[light]);
        if (planes_block(w, p, s.l, s.tmin, s.tmax)) {
            seen[k] = false;
            continue;
        }
        set_lane(q, k, p, s.l, s.tmin, s.tmax);
        init_ray(r, k, p, s.l, s.tmin, s.tmax);
        valid[k] = -1, any = true;
    }
    if (any) rtcOccluded8(valid, w.scene, &q.rtc, &r);
    for (int k = 0; k < count; ++k)
        if (valid[k]) seen[k] = r.tfar[k] >= 0;
}

// Pixels (i0, j) .. (i0 + count - 1, j), traced as packets.
void shade8(const World& w, const Camera& cam, int i0, int j, int count, V* colors) {
    const V eye = cam.eye;
    V d[kLanes];
    for (int k = 0; k < count; ++k) d[k] = cam.ray(i0 + k, j);
    Hit h[kLanes];
    closest8(w, eye, d, count, h);
    // Per lane, a bit per light (main() sends scenes of more lights down the single-ray path).
    std::uint64_t hidden[kLanes] = {};
    const std::size_t nl = w.ref.shadows ? w.ref.lights.size() : 0;
    for (std::size_t l = 0; l < nl; ++l) {
        bool s[kLanes];
        seen8(w, eye, d, h, count, l, s);
        for (int k = 0; k < count; ++k) hidden[k] |= std::uint64_t(!s[k]) << l;
    }
    for (int k = 0; k < count; ++k)
        colors[k] = h[k].object < 0 ? from(w.ref.background)
                                    : phong(w, h[k], eye, d[k], [&](std::size_t l, const ShadowRay&) {
                                          return !(hidden[k] >> l & 1);
                                      });
}

// round(255 c), c clamped to [0, 1], ties up (libm's lround cost 3 % of the instructions).
std::uint8_t to_byte(double c) {
    const double v = 255 * std::clamp(c, 0.0, 1.0);
    const int whole = static_cast<int>(v);
    return static_cast<std::uint8_t>(v - whole >= 0.5 ? whole + 1 : whole);
}

lat::Image8 render(const World& w, bool packets) {
    const Camera cam(w.ref.camera);
    lat::Image8 img{cam.width, cam.height, std::vector<std::uint8_t>(3 * std::size_t(cam.width) * cam.height)};
    tbb::parallel_for(tbb::blocked_range<int>(0, cam.height), [&](const tbb::blocked_range<int>& rows) {
        for (int j = rows.begin(); j != rows.end(); ++j)
            for (int i = 0; i < cam.width; i += kLanes) {
                const int count = std::min(kLanes, cam.width - i);
                V c[kLanes];
                if (packets)
                    shade8(w, cam, i, j, count, c);
                else
                    for (int k = 0; k < count; ++k) c[k] = shade(w, cam.eye, cam.ray(i + k, j));
                for (int k = 0; k < count; ++k) {
                    std::uint8_t* px = &img.rgb[3 * (std::size_t(j) * cam.width + std::size_t(i + k))];
                    px[0] = to_byte(c[k].x), px[1] = to_byte(c[k].y), px[2] = to_byte(c[k].z);
                }
            }
    });
    return img;
}

double ms_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"An independent Embree tracer for lattice-reference/1 scenes (timing yardstick)"};
    std::string scene_path, out_path, geometry = "user";
    int threads = 0, rounds = 1;
    app.add_option("scene", scene_path, "Scene file (lattice-reference/1)")->required();
    app.add_option("-o,--output", out_path, "Output PNG")->required();
    app.add_option("--threads", threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 4096));
    app.add_option("--geometry", geometry, "user: double-precision user geometry; native: Embree's float primitives")
        ->check(CLI::IsMember({"user", "native"}));
    app.add_option("--rounds", rounds, "Renders timed (the median is reported)")->check(CLI::Range(1, 1000));
    bool packets = false;
    app.add_flag("--packets", packets, "Rays 8 at a time (rtcIntersect8 / rtcOccluded8: a row's 8 pixels, their shadow rays)");
    CLI11_PARSE(app, argc, argv);
    try {
        const int n = threads > 0 ? threads : int(tbb::this_task_arena::max_concurrency());
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(n));
        World w;
        w.ref = reftrace::load_scene(scene_path);
        if (packets && w.ref.lights.size() > 64)  // shade8 keeps a bit per light
            throw std::runtime_error(scene_path + ": lights: " + std::to_string(w.ref.lights.size()) +
                                     " (--packets takes at most 64)");
        const reftrace::Camera& cam = w.ref.camera;
        if (cam.width < 1 || cam.height < 1 || std::int64_t(cam.width) * cam.height > (std::int64_t{1} << 26))
            throw std::runtime_error(scene_path + ": camera: " + std::to_string(cam.width) + " x " +
                                     std::to_string(cam.height) + " pixels (1 to 2^26 pixels)");
        w.native = geometry == "native";
        const std::string config = "threads=" + std::to_string(n);
        w.device = rtcNewDevice(config.c_str());
        if (!w.device) throw std::runtime_error("Embree: cannot create a device");
        const auto t0 = std::chrono::steady_clock::now();
        build_world(w);
        if (rtcGetDeviceError(w.device) != RTC_ERROR_NONE) throw std::runtime_error("Embree: build failed");
        const double build_ms = ms_since(t0);
        std::vector<double> times;
        lat::Image8 img;
        for (int r = 0; r < rounds; ++r) {
            const auto t = std::chrono::steady_clock::now();
            img = render(w, packets);
            times.push_back(ms_since(t));
        }
        lat::write_png(out_path, img);
        std::vector<double> sorted = times;
        std::sort(sorted.begin(), sorted.end());
        std::printf("{\"scene\": \"%s\", \"geometry\": \"%s\", \"packets\": %s, \"threads\": %d, \"build_ms\": %.3f, \"render_ms\": %.3f, \"rounds_ms\": [",
                    scene_path.c_str(), geometry.c_str(), packets ? "true" : "false", n, build_ms, sorted[sorted.size() / 2]);
        for (std::size_t k = 0; k < times.size(); ++k) std::printf("%s%.3f", k ? ", " : "", times[k]);
        std::printf("]}\n");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "embree_tracer: %s\n", e.what());
        return 2;
    }
    return 0;
}
