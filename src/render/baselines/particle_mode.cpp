#include "render/baselines/particle_mode.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "geometry/chain.h"
#include "render/core/camera.h"
#include "render/core/sampler.h"
#include "render/core/traced_scene.h"
#include "render/baselines/scene_parts.h"
#include "render/core/shading.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/progress.h"
#include "util/threads.h"

namespace lat {
namespace {

constexpr int kTile = 16;

// A perspective view: camera-space depth z along w, and the image plane in sample units.
struct View {
    Vec3 eye, u, v, w;
    double fx = 1, fy = 1, cx = 0, cy = 0;  // pixel = (c + f x / z)
    double near = 1e-9;

    bool project(Vec3 p, double& px, double& py, double& z) const {
        const Vec3 d = p - eye;
        z = dot(d, w);
        if (z <= near) return false;
        px = cx + fx * dot(d, u) / z;
        py = cy - fy * dot(d, v) / z;
        return true;
    }
};

View camera_view(const Camera& c) {
    View view;
    view.eye = c.eye;
    view.w = normalize(c.look_at - c.eye);
    view.u = normalize(cross(view.w, c.up));
    view.v = cross(view.u, view.w);
    const double h = std::tan(c.fov_y_deg * M_PI / 360.0);
    view.fy = c.height / (2 * h);
    view.fx = view.fy;  // square pixels, as PinholeCamera
    view.cx = c.width / 2.0;
    view.cy = c.height / 2.0;
    return view;
}

// A particle as the view sees it: its axis in image units, the projected radius at each end,
// the camera depth of each end and the world radius (for the near side's depth).
struct Splat {
    double ax, ay, bx, by, ra, rb, za, zb, r;
    double x0, y0, x1, y1;  // bounds in image units
};

bool make_splat(const View& view, const Particle& p, Splat& s) {
    if (!view.project(p.a, s.ax, s.ay, s.za) || !view.project(p.b, s.bx, s.by, s.zb)) return false;
    s.ra = p.radius * view.fy / s.za;
    s.rb = p.radius * view.fy / s.zb;
    s.r = p.radius;
    s.x0 = std::min(s.ax - s.ra, s.bx - s.rb);
    s.x1 = std::max(s.ax + s.ra, s.bx + s.rb);
    s.y0 = std::min(s.ay - s.ra, s.by - s.rb);
    s.y1 = std::max(s.ay + s.ra, s.by + s.rb);
    return true;
}

// Whether the splat covers image point (x, y), and the depth of the hair's near side there.
bool cover(const Splat& s, double x, double y, double& z) {
    const double ux = s.bx - s.ax, uy = s.by - s.ay, wx = x - s.ax, wy = y - s.ay;
    const double uu = ux * ux + uy * uy;
    const double t = uu > 0 ? std::clamp((wx * ux + wy * uy) / uu, 0.0, 1.0) : 0.0;
    const double dx = wx - t * ux, dy = wy - t * uy, rp = s.ra + t * (s.rb - s.ra);
    const double dd = dx * dx + dy * dy;
    if (dd > rp * rp) return false;
    z = s.za + t * (s.zb - s.za) - s.r * std::sqrt(std::max(0.0, 1 - dd / (rp * rp)));
    return true;
}

// Depth of the particles nearest a light, seen from it (perspective toward their bounding
// sphere); visibility() is the share of a 3 x 3 texel neighbourhood at which p is not behind.
class ShadowMap {
public:
    ShadowMap(Vec3 light, const std::vector<Particle>& ps, Vec3 centre, double radius, int n) : n_(n) {
        const double dist = length(centre - light);
        if (ps.empty() || dist <= radius * 1.001) return;  // a light inside the fur: no map
        view_.eye = light;
        view_.w = (centre - light) / dist;
        const Vec3 up = std::abs(view_.w.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0};
        view_.u = normalize(cross(view_.w, up));
        view_.v = cross(view_.u, view_.w);
        const double tan_half = radius / std::sqrt(dist * dist - radius * radius);
        view_.fx = view_.fy = n / (2 * tan_half);
        view_.cx = view_.cy = n / 2.0;
        depth_.assign(static_cast<std::size_t>(n) * n, std::numeric_limits<float>::infinity());
        double thickest = 0;
        for (const Particle& p : ps) {
            thickest = std::max(thickest, p.radius);
            Splat s;
            if (!make_splat(view_, p, s)) continue;
            const int i0 = std::max(0, static_cast<int>(std::floor(s.x0))), i1 = std::min(n - 1, static_cast<int>(s.x1));
            const int j0 = std::max(0, static_cast<int>(std::floor(s.y0))), j1 = std::min(n - 1, static_cast<int>(s.y1));
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) {
                    double z;
                    if (!cover(s, i + 0.5, j + 0.5, z)) continue;
                    float& d = depth_[static_cast<std::size_t>(j) * n + i];
                    d = std::min(d, static_cast<float>(z));
                }
        }
        bias_ = 2 * thickest;
        valid_ = true;
    }

    double visibility(Vec3 p) const {
        double x, y, z;
        if (!valid_ || !view_.project(p, x, y, z)) return 1.0;
        const int ci = static_cast<int>(std::floor(x)), cj = static_cast<int>(std::floor(y));
        int lit = 0;
        for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
                const int i = ci + di, j = cj + dj;
                if (i < 0 || j < 0 || i >= n_ || j >= n_ ||
                    z - bias_ <= static_cast<double>(depth_[static_cast<std::size_t>(j) * n_ + i]))
                    ++lit;
            }
        return lit / 9.0;
    }

    std::uint64_t bytes() const { return depth_.size() * sizeof(float); }

private:
    View view_;
    int n_;
    std::vector<float> depth_;
    double bias_ = 0;
    bool valid_ = false;
};

// Light i reaching the start of shadow ray r (for_each_light's visible): the ray against the
// base, then the particles' map.
double light_visibility(const TracedScene& base, const std::vector<ShadowMap>& maps, std::size_t i,
                        const Ray& r, double tmin, double tmax, std::uint32_t self) {
    if (base.occluded(r, tmin, tmax, self)) return 0.0;
    return maps[i].visibility(r.o);
}

// Kajiya-Kay (1989): diffuse by the sine between tangent and light, specular by the sine
// between tangent and half vector (the cone of reflections about the strand), flat over the
// particle as a particle system shades.
Vec3 shade_particle(const Scene& s, const TracedScene& base, const std::vector<ShadowMap>& maps,
                    const Particle& p, ShadeState& state) {
    const Material& m = s.materials[p.material];
    const Vec3 mid = (p.a + p.b) * 0.5;
    const Vec3 axis = p.b - p.a;
    const Vec3 view = normalize(s.camera.eye - mid);
    // A point particle has no tangent: take the one across the view, which shades as a disc.
    const Vec3 t = length_squared(axis) > 0 ? normalize(axis) : normalize(cross(view, Vec3{0, 0, 1}) + Vec3{1e-9, 0, 0});
    Vec3 c = m.ka * m.color * s.ambient;
    // The light's intensity and what the strand reflects of it, apart: the share that arrives
    // scales the intensity first.
    struct Term {
        Vec3 intensity, reflected;
        bool operator==(const Term&) const = default;
    };
    const auto term = [&](const PointLight& light, Vec3 l) {
        const double tl = dot(t, l), th = dot(t, normalize(l + view));
        const double diffuse = m.kd * std::sqrt(std::max(0.0, 1 - tl * tl));
        const double spec = m.ks * std::pow(std::sqrt(std::max(0.0, 1 - th * th)), m.shininess);
        const Vec3 reflected = diffuse * m.color + Vec3{spec, spec, spec};
        return reflected == Vec3{} ? Term{} : Term{light.intensity, reflected};
    };
    const auto visible = [&](std::size_t i, const Ray& r, double tmin, double tmax, double,
                             const auto&) {
        return light_visibility(base, maps, i, r, tmin, tmax, EmbreeAccel::kNoObject);
    };
    const auto lit = [&](const Term& k, double seen) { c += seen * k.intensity * k.reflected; };
    for_each_light(base, mid, state, term, visible, lit);
    return c;
}

// Phong, as exact mode shades; the particles' shadows from their maps.
Vec3 shade_base(const TracedScene& base, const std::vector<ShadowMap>& maps, const Ray& ray,
                const SurfaceHit& hit, ShadeState& state) {
    const auto visible = [&](std::size_t i, const Ray& r, double tmin, double tmax, double,
                             const auto&) {
        return light_visibility(base, maps, i, r, tmin, tmax, hit.object);
    };
    return shade_with(base, ray, hit, state, visible);
}

}  // namespace

ParticleSet make_particles(const Scene& scene) {
    ParticleSet set;
    for (const std::size_t oi : instance_objects(scene)) {
        const SceneObject o = scene.object(oi);
        const Primitive& prim = scene.primitives[static_cast<std::size_t>(o.primitive)];
        const ChainShape* chain = prim.shape ? as_chain(*prim.shape) : nullptr;
        if (!chain)
            throw InputError(located_message(scene.file, o.where,
                                             "particle mode needs a sphere/cylinder chain primitive; '" +
                                                 prim.name + "' is another object"));
        const double scale = std::cbrt(std::abs(determinant(o.xf.forward().m)));
        std::vector<bool> joined(chain->spheres().size(), false);
        for (const ChainCylinder& c : chain->cylinders()) {
            joined[static_cast<std::size_t>(c.from)] = joined[static_cast<std::size_t>(c.to)] = true;
            const Vec3 a = o.xf.point(chain->spheres()[static_cast<std::size_t>(c.from)].center);
            const Vec3 b = o.xf.point(chain->spheres()[static_cast<std::size_t>(c.to)].center);
            const double r = c.radius * scale;
            const int pieces = std::max(1, static_cast<int>(std::ceil(length(b - a) / (2 * r))));
            for (int k = 0; k < pieces; ++k)
                set.particles.push_back({a + (b - a) * (double(k) / pieces), a + (b - a) * (double(k + 1) / pieces),
                                         r, o.material});
        }
        for (std::size_t k = 0; k < joined.size(); ++k)
            if (!joined[k]) {
                const Vec3 c = o.xf.point(chain->spheres()[k].center);
                set.particles.push_back({c, c, chain->spheres()[k].radius * scale, o.material});
            }
    }
    return set;
}

RenderOutput render_particles(const Scene& scene, const ParticleSet& set, const ParticleOptions& opt) {
    const auto start = std::chrono::steady_clock::now();
    const Scene base_only = base_scene(scene);
    const TracedScene base(base_only);
    const std::vector<Particle>& ps = set.particles;

    // Shadow maps, one per light, around the particles' bounding sphere.
    Bounds3 box;
    for (const Particle& p : ps) {
        box = merge(box, expand(Bounds3{min(p.a, p.b), max(p.a, p.b)}, p.radius));
    }
    std::vector<ShadowMap> maps;
    const Vec3 centre = ps.empty() ? Vec3{} : (box.lo + box.hi) * 0.5;
    const double radius = ps.empty() ? 0 : length(box.hi - box.lo) * 0.5;
    for (const PointLight& l : scene.lights)
        maps.emplace_back(l.position, scene.shadows ? ps : std::vector<Particle>{}, centre, radius,
                          opt.shadow_map_size);

    // Shading, one colour per particle.
    std::vector<Vec3> colour(ps.size());
    std::atomic<std::uint64_t> shadow{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ps.size(), 1024), [&](const auto& r) {
        ShadeState state;
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            colour[i] = shade_particle(scene, base, maps, ps[i], state);
        shadow.fetch_add(state.shadow_rays, std::memory_order_relaxed);
    });

    // Splats, binned to tiles in particle order (the order that breaks depth ties).
    const Camera& cam = scene.camera;
    const int w = cam.width, h = cam.height;
    const View view = camera_view(cam);
    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    std::vector<Splat> splats(ps.size());
    std::vector<std::vector<std::uint32_t>> bins(static_cast<std::size_t>(tiles_x) * tiles_y);
    for (std::size_t i = 0; i < ps.size(); ++i) {
        Splat& s = splats[i];
        if (!make_splat(view, ps[i], s) || s.x1 < 0 || s.y1 < 0 || s.x0 >= w || s.y0 >= h) continue;
        const int tx0 = std::max(0, static_cast<int>(s.x0) / kTile), tx1 = std::min(tiles_x - 1, static_cast<int>(s.x1) / kTile);
        const int ty0 = std::max(0, static_cast<int>(s.y0) / kTile), ty1 = std::min(tiles_y - 1, static_cast<int>(s.y1) / kTile);
        for (int ty = ty0; ty <= ty1; ++ty)
            for (int tx = tx0; tx <= tx1; ++tx)
                bins[static_cast<std::size_t>(ty) * tiles_x + tx].push_back(static_cast<std::uint32_t>(i));
    }

    int nx, ny;
    stratify(std::max(1, opt.spp), nx, ny);
    const int spp = nx * ny;
    RenderOutput out;
    out.radiance = {w, h, std::vector<float>(static_cast<std::size_t>(w) * h * 3)};
    out.display = {w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3)};
    std::atomic<std::uint64_t> primary{0};
    ProgressBar bar("particles", static_cast<std::uint64_t>(tiles_x) * tiles_y, opt.progress);
    const PinholeCamera rays(cam);
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y, 1), [&](const tbb::blocked_range<int>& range) {
        std::vector<double> depth;
        std::vector<Vec3> rgb;
        for (int tile = range.begin(); tile != range.end(); ++tile) {
            if (interrupted()) return;
            const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
            const int tw = std::min(kTile, w - x0), th = std::min(kTile, h - y0);
            const int sw = tw * nx;  // samples per tile row
            depth.assign(static_cast<std::size_t>(sw) * th * ny, std::numeric_limits<double>::infinity());
            rgb.assign(depth.size(), scene.background);
            ShadeState state;
            // The base, ray traced at every sample.
            for (int sy = 0; sy < th * ny; ++sy)
                for (int sx = 0; sx < sw; ++sx) {
                    const double px = x0 + (sx + 0.5) / nx, py = y0 + (sy + 0.5) / ny;
                    const Ray ray = rays.ray(px, py, 0.0, 0.0);
                    SurfaceHit hit;
                    const std::size_t k = static_cast<std::size_t>(sy) * sw + sx;
                    if (base.intersect(ray, 0.0, kInfinity, hit)) {
                        depth[k] = hit.t * dot(ray.d, view.w);
                        rgb[k] = shade_base(base, maps, ray, hit, state);
                    }
                }
            primary.fetch_add(static_cast<std::uint64_t>(sw) * th * ny, std::memory_order_relaxed);
            // The particles, depth-tested into the same samples.
            for (const std::uint32_t pi : bins[static_cast<std::size_t>(tile)]) {
                const Splat& s = splats[pi];
                const int sx0 = std::max(0, static_cast<int>(std::floor((s.x0 - x0) * nx - 0.5)));
                const int sx1 = std::min(sw - 1, static_cast<int>(std::ceil((s.x1 - x0) * nx)));
                const int sy0 = std::max(0, static_cast<int>(std::floor((s.y0 - y0) * ny - 0.5)));
                const int sy1 = std::min(th * ny - 1, static_cast<int>(std::ceil((s.y1 - y0) * ny)));
                for (int sy = sy0; sy <= sy1; ++sy)
                    for (int sx = sx0; sx <= sx1; ++sx) {
                        double z;
                        if (!cover(s, x0 + (sx + 0.5) / nx, y0 + (sy + 0.5) / ny, z)) continue;
                        const std::size_t k = static_cast<std::size_t>(sy) * sw + sx;
                        if (z < depth[k]) {
                            depth[k] = z;
                            rgb[k] = colour[pi];
                        }
                    }
            }
            // Box filter into pixels.
            for (int j = 0; j < th; ++j)
                for (int i = 0; i < tw; ++i) {
                    Vec3 sum, clamped;
                    for (int b = 0; b < ny; ++b)
                        for (int a = 0; a < nx; ++a) {
                            const Vec3 c = rgb[static_cast<std::size_t>(j * ny + b) * sw + i * nx + a];
                            sum += c;
                            clamped += Vec3{std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0),
                                            std::clamp(c.z, 0.0, 1.0)};
                        }
                    const std::size_t px = (static_cast<std::size_t>(y0 + j) * w + x0 + i) * 3;
                    for (std::size_t ch = 0; ch < 3; ++ch) {
                        out.radiance.rgb[px + ch] = static_cast<float>(sum[ch] / spp);
                        out.display.rgb[px + ch] = to_byte(clamped[ch] / spp);
                    }
                }
            shadow.fetch_add(state.shadow_rays, std::memory_order_relaxed);
            bar.add(1);
        }
    });
    bar.finish();
    throw_if_interrupted();
    out.stats.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    out.stats.primary_rays = primary.load();
    out.stats.shadow_rays = shadow.load();
    out.stats.threads = thread_count();
    // Splats are depth-tested at fixed points: the cell centres whatever the sampler.
    out.stats.sampler = spp == 1 ? "centre" : sampler_description(SamplerKind::kGrid).name;
    return out;
}

}  // namespace lat
