#include "scene/scatter.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "geometry/named_shapes.h"
#include "geometry/surface_sampler.h"
#include "scene/scene_loader.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/progress.h"

namespace lat {
namespace {

struct ScatterParams {
    int primitive = -1;
    std::uint32_t material = 0;
    std::size_t count = 0;
    std::uint64_t seed = 0;
    bool align_normal = true;
    bool random_twist = true;
    double twist = 0;  // radians, when not random
    double scale_lo = 1, scale_hi = 1;
    double cos_tilt = 1;  // cosine of the largest tilt
    double min_distance = 0;  // Poisson disk when > 0
    Vec3 comb{1, 0, 0};
};

Transform user_transform(const JsonValue& on) {
    if (auto t = on.find("transform")) return parse_transform(*t);
    return {};
}

std::optional<Bounds3> parse_box(const JsonValue& v) {
    auto b = v.find("box");
    if (!b) return std::nullopt;
    if (!b->is_array() || b->size() != 2) b->fail("expected [[x0, y0, z0], [x1, y1, z1]]");
    const Vec3 lo = (*b)[0].vec3(), hi = (*b)[1].vec3();
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
        b->fail("the first corner must be below the second on every axis");
    return Bounds3{lo, hi};
}

// The sampler for the surface of the object `on`, clipped to the scatter's box.
std::unique_ptr<SurfaceSampler> sampler_for(const JsonValue& v, const JsonValue& on,
                                            const ObjectParser& parser) {
    const std::string type = on.at("type").string();
    const Transform user = user_transform(on);
    const std::optional<Bounds3> box = parse_box(v);
    if (type == "mesh") {
        if (box) v.at("box").fail("a box clips quadrics only; a mesh is scattered over whole");
        std::shared_ptr<const TriangleMeshShape> mesh = parser.mesh(on);
        try {
            return make_mesh_sampler(std::move(mesh), user);
        } catch (const InputError& e) {
            v.at("on").fail(e.what());  // (the sampler's messages have no location)
        }
    }
    auto axis = [&] { return on.has("axis") ? normalize(on.at("axis").direction()) : Vec3{0, 0, 1}; };
    ParamKind kind;
    Transform place;
    double minor = 0;
    if (type == "sphere" || type == "ellipsoid") {
        kind = ParamKind::kSphere;
        const Vec3 r = type == "sphere" ? Vec3{1, 1, 1} * on.at("radius").positive() : on.at("radii").vec3();
        place = Transform::translate(on.vec3_or("center", {})) * Transform::scale(r);
    } else if (type == "torus") {
        kind = ParamKind::kTorus;
        const double R = on.at("major_radius").positive();
        minor = on.at("minor_radius").positive() / R;
        place = frame_transform(on.vec3_or("center", {}), axis()) * Transform::scale({R, R, R});
    } else if (type == "halfspace") {
        kind = ParamKind::kPlane;
        place = frame_transform(on.vec3_or("point", {}), on.at("normal").direction());
    } else if (type == "cylinder" || type == "cone" || type == "paraboloid") {
        double a = 1;
        if (type == "cylinder") a = on.at("radius").positive();
        if (type == "cone") a = std::tan(on.at("half_angle_deg").number() * M_PI / 180);
        if (type == "paraboloid")
            a = on.at("radius").positive() / std::sqrt(on.has("height") ? on.at("height").positive() : 1.0);
        kind = type == "cylinder" ? ParamKind::kCylinder
                                  : (type == "cone" ? ParamKind::kCone : ParamKind::kParaboloid);
        const char* origin = type == "cylinder" ? "center" : (type == "cone" ? "apex" : "vertex");
        place = frame_transform(on.vec3_or(origin, {}), axis()) * Transform::scale({a, a, 1});
    } else if (type == "hyperboloid1" || type == "hyperboloid2") {
        kind = type == "hyperboloid1" ? ParamKind::kHyperboloid1 : ParamKind::kHyperboloid2;
        place = frame_transform(on.vec3_or("center", {}), axis()) * Transform::scale(on.at("radii").vec3());
    } else {
        on.at("type").fail("cannot scatter over a " + type +
                           " (scatter over a sphere, ellipsoid, cylinder, cone, paraboloid, "
                           "hyperboloid1, hyperboloid2, torus, halfspace or mesh)");
    }
    if (param_kind_unbounded(kind) && !box)
        v.fail("missing field 'box': a " + type + " is unbounded, so the scatter needs a box to have finite area");
    try {
        return make_param_sampler(kind, minor, user * place, box);
    } catch (const InputError& e) {
        (box ? v.at("box") : v).fail(e.what());
    }
}

ScatterParams parse_params(const JsonValue& v, const ObjectParser& parser,
                           const std::vector<Primitive>& primitives, double area) {
    ScatterParams p;
    const JsonValue prim = v.at("primitive");
    for (std::size_t i = 0; i < primitives.size(); ++i)
        if (primitives[i].name == prim.string()) p.primitive = static_cast<int>(i);
    if (p.primitive < 0) prim.fail("unknown primitive '" + prim.string() + "'");
    p.material = parser.material_index(v.at("material"));
    if (v.has("count") == v.has("density")) v.fail("a scatter needs exactly one of 'count' or 'density'");
    double n;
    if (auto c = v.find("count")) {
        n = c->non_negative();
        if (n != std::floor(n)) c->fail("expected a whole number");
    } else {
        n = std::round(v.at("density").non_negative() * area);
    }
    if (n > static_cast<double>(kMaxScatterCount))
        (v.has("count") ? v.at("count") : v.at("density"))
            .fail(std::to_string(static_cast<long long>(std::min(n, 1e18))) +
                  " instances is over the limit of " + std::to_string(kMaxScatterCount) +
                  " (the surface's area is " + std::to_string(area) + ")");
    p.count = static_cast<std::size_t>(n);
    if (auto s = v.find("seed")) p.seed = static_cast<std::uint64_t>(static_cast<std::int64_t>(s->integer()));
    if (auto a = v.find("align")) {
        const std::string al = a->string();
        if (al != "normal" && al != "up") a->fail("expected \"normal\" or \"up\"");
        p.align_normal = al == "normal";
    }
    if (auto t = v.find("twist")) {
        if (t->is_string()) {
            if (t->string() != "random") t->fail("expected \"random\" or an angle in degrees");
        } else {
            p.random_twist = false;
            p.twist = t->number() * M_PI / 180;
        }
    }
    if (auto s = v.find("scale")) {
        if (s->is_array()) {
            if (s->size() != 2) s->fail("expected a number or [min, max]");
            p.scale_lo = (*s)[0].positive();
            p.scale_hi = (*s)[1].positive();
            if (p.scale_lo > p.scale_hi) s->fail("min is over max");
        } else {
            p.scale_lo = p.scale_hi = s->positive();
        }
    }
    if (auto t = v.find("tilt_deg")) {
        const double deg = t->non_negative();
        if (deg > 90) t->fail("must be between 0 and 90 degrees");
        p.cos_tilt = std::cos(deg * M_PI / 180);
    }
    if (auto c = v.find("comb")) p.comb = normalize(c->direction());
    if (auto d = v.find("min_distance")) p.min_distance = d->positive();
    if (auto pd = v.find("poisson"); pd && pd->boolean() && p.min_distance == 0 && p.count > 0)
        p.min_distance = 0.6 * std::sqrt(area / static_cast<double>(p.count));
    return p;
}

// A unit vector across n: the comb direction with its normal part removed (another axis when
// the comb runs along n), so neighbouring instances share their frame.
Vec3 across(Vec3 n, Vec3 comb) {
    Vec3 t = comb - dot(comb, n) * n;
    if (length_squared(t) < 1e-6) {
        const Vec3 other = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        t = other - dot(other, n) * n;
    }
    return normalize(t);
}

// The instance's transform: its root on the surface point, its z axis along the (tilted)
// normal, turned about it by the twist, scaled. Draws come from the instance's own stream.
Affine placement(const SurfaceSample& s, const ScatterParams& p, Vec3 root, CounterRng& rng) {
    const Vec3 n = p.align_normal ? s.n : Vec3{0, 0, 1};
    const Vec3 t = across(n, p.comb), b = cross(n, t);
    const double cos_t = 1 - rng.uniform() * (1 - p.cos_tilt);  // uniform over the cone's cap
    const double phi = 2 * M_PI * rng.uniform();
    const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
    const Vec3 z = normalize(cos_t * n + sin_t * (std::cos(phi) * t + std::sin(phi) * b));
    const double twist = p.random_twist ? 2 * M_PI * rng.uniform() : p.twist;
    const Vec3 x0 = across(z, t);
    const Vec3 x = std::cos(twist) * x0 + std::sin(twist) * cross(z, x0);
    const Vec3 y = cross(z, x);
    const double k = p.scale_lo + (p.scale_hi - p.scale_lo) * rng.uniform();
    Affine a;
    // Adding +0 turns -0 into 0: JSON writers drop the sign of zero, and `lattice scatter`
    // must write matrices that read back bit for bit.
    for (std::size_t r = 0; r < 3; ++r) a.m.r[r] = Vec3{x[r], y[r], z[r]} * k + Vec3{0, 0, 0};
    a.t = s.p - a.m * root + Vec3{0, 0, 0};
    return a;  // a rotation times k > 0, singular only by overflow (expand_scatter checks)
}

// Poisson-disk (dart throwing): candidates in stream order, each kept when no kept point lies
// within d. Sequential, so the result does not depend on threads.
std::vector<SurfaceSample> poisson_samples(const SurfaceSampler& sampler, const ScatterParams& p,
                                           const JsonValue& v) {
    const double d = p.min_distance;
    const auto fail = [&](const std::string& why) {
        (v.has("min_distance") ? v.at("min_distance") : v).fail(why);
    };
    // Candidates are filed in cells of side d counted from the samples' bounds, at most this
    // many a side, so that a cell's number is exact in a double and in an integer.
    constexpr double kMaxCells = 0x1p40;
    const Bounds3 b = sampler.bounds();
    const Vec3 e = b.extent();
    if (!(std::max({e.x, e.y, e.z}) / d <= kMaxCells))
        fail("a minimum distance of " + format_number(d) + " is too small for a surface " +
             format_number(std::max({e.x, e.y, e.z})) + " across (at most 2^40 distances)");
    // Points d apart are the centres of disjoint balls of diameter d inside the bounds grown by
    // d / 2: a count that cannot fit is refused now rather than after 50 tries an instance.
    const double most = (e.x / d + 1) * (e.y / d + 1) * (e.z / d + 1) * (6 / M_PI);
    if (static_cast<double>(p.count) > most * (1 + 1e-9) + 1)
        fail(std::to_string(p.count) + " instances cannot be " + format_number(d) +
             " apart on this surface: its bounds hold at most " +
             std::to_string(static_cast<long long>(most)) +
             " points that far apart (lower the count or the distance)");
    std::vector<SurfaceSample> kept;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
    auto cell = [&](Vec3 q, int dx, int dy, int dz) {
        const auto c = [&](double x, double lo, int o) {
            // (A sample outside the bounds by rounding is at most a cell outside.)
            const double k = std::clamp(std::floor((x - lo) / d), -1.0, kMaxCells + 1);
            return static_cast<std::uint64_t>(static_cast<std::int64_t>(k) + o) & 0x1FFFFF;
        };
        return (c(q.x, b.lo.x, dx) << 42) | (c(q.y, b.lo.y, dy) << 21) | c(q.z, b.lo.z, dz);
    };
    const std::size_t tries = 50 * p.count + 1000;
    for (std::size_t k = 0; k < tries && kept.size() < p.count; ++k) {
        CounterRng rng(p.seed, 2 * k);
        const SurfaceSample s = sampler.sample(rng);
        bool free = true;
        for (int dx = -1; dx <= 1 && free; ++dx)
            for (int dy = -1; dy <= 1 && free; ++dy)
                for (int dz = -1; dz <= 1 && free; ++dz)
                    if (auto it = grid.find(cell(s.p, dx, dy, dz)); it != grid.end())
                        for (const std::uint32_t i : it->second)
                            if (length_squared(kept[i].p - s.p) < d * d) free = false;
        if (!free) continue;
        grid[cell(s.p, 0, 0, 0)].push_back(static_cast<std::uint32_t>(kept.size()));
        kept.push_back(s);
    }
    if (kept.size() < p.count)
        (v.has("min_distance") ? v.at("min_distance") : v)
            .fail("only " + std::to_string(kept.size()) + " of " + std::to_string(p.count) +
                  " instances fit at a minimum distance of " + std::to_string(d) +
                  " (lower the count or the distance)");
    return kept;
}

// Refuses `count` instances that would not fit, with the `before` objects already placed, in
// the memory available (unknown: any number).
void require_memory_for(std::size_t count, std::size_t before, const JsonValue& v) {
    const double need = static_cast<double>(count + before) * kScatterBytesPerInstance;
    const std::size_t available = available_memory_bytes();
    if (available == 0 || need <= static_cast<double>(available)) return;
    (v.has("count") ? v.at("count") : v.at("density"))
        .fail(std::to_string(count) + " instances need about " + human_bytes(need) +
              " of memory with the objects before them, over the " +
              human_bytes(static_cast<double>(available)) +
              " available (lower the count or the density)");
}

}  // namespace

Vec3 primitive_root(const Primitive& prim) {
    if (prim.lattice) {
        const LatticeSpec& l = *prim.lattice;
        return {0.5 * l.cells[0] * l.sigma, 0.5 * l.cells[1] * l.sigma, 0};
    }
    const Bounds3 b = prim.shape->bounds();
    return {0.5 * (b.lo.x + b.hi.x), 0.5 * (b.lo.y + b.hi.y), b.lo.z};
}

void expand_scatter(const JsonValue& v, const JsonValue& on, const ObjectParser& parser,
                    const std::vector<Primitive>& primitives, std::size_t before, ScatterGroup& out,
                    bool progress) {
    v.allow_keys({"type", "name", "primitive", "on", "count", "density", "seed", "align", "twist",
                  "scale", "tilt_deg", "material", "box", "min_distance", "poisson", "comb"},
                 "a scatter");
    const std::unique_ptr<SurfaceSampler> sampler = sampler_for(v, on, parser);
    const ScatterParams p = parse_params(v, parser, primitives, sampler->area());
    const Primitive& prim = primitives[static_cast<std::size_t>(p.primitive)];
    const Vec3 root = primitive_root(prim);
    require_memory_for(p.count, before, v);
    // Each instance draws from its own streams (2i: its point, 2i + 1: its placement), so the
    // instances are placed in parallel, alike for any number of threads.
    std::vector<SurfaceSample> points;
    if (p.min_distance > 0) points = poisson_samples(*sampler, p, v);
    const std::size_t n = p.min_distance > 0 ? points.size() : p.count;
    out.shape = prim.shape;
    out.material = p.material;
    out.primitive = p.primitive;
    out.where = v.path();
    out.placements.resize(n);
    ProgressBar bar("place", n, progress, 1000);
    // The first instance whose placement makes no transform (Scene::transform inverts each).
    std::atomic<std::size_t> first_bad{n};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& range) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
            CounterRng point_rng(p.seed, 2 * i), rng(p.seed, 2 * i + 1);
            const SurfaceSample s = points.empty() ? sampler->sample(point_rng) : points[i];
            out.placements[i] = placement(s, p, root, rng);
            if (!Transform::from_affine(out.placements[i])) {
                std::size_t b = first_bad.load();
                while (i < b && !first_bad.compare_exchange_weak(b, i)) {
                }
            }
        }
        bar.add(range.size());
    });
    if (const std::size_t i = first_bad.load(); i < n) {
        std::string scale = format_number(p.scale_lo);
        if (p.scale_hi != p.scale_lo) scale = "[" + scale + ", " + format_number(p.scale_hi) + "]";
        (v.has("scale") ? v.at("scale") : v)
            .fail("instance " + std::to_string(i) +
                  " has no invertible finite placement: a scale of " + scale +
                  " is too extreme for this primitive and surface");
    }
}

}  // namespace lat
