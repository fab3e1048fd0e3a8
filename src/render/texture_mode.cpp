#include "render/texture_mode.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "geometry/sphere.h"
#include "render/render_scene.h"
#include "render/scene_parts.h"
#include "render/shading.h"
#include "util/error.h"
#include "util/progress.h"

namespace lat {
namespace {

// Where an instance of p is rooted, in p's coordinates (as scatter roots it).
Vec3 primitive_root(const Primitive& p) {
    if (p.lattice)
        return {p.lattice->cells[0] * p.lattice->sigma / 2, p.lattice->cells[1] * p.lattice->sigma / 2, 0};
    const Bounds3 b = p.shape->bounds();
    return {(b.lo.x + b.hi.x) / 2, (b.lo.y + b.hi.y) / 2, b.lo.z};
}

const SphereShape* as_sphere(const SceneObject& o) {
    return o.primitive < 0 ? dynamic_cast<const SphereShape*>(o.shape.get()) : nullptr;
}

Vec3 surface_point(const SceneObject& o, const SphereShape& s, Vec3 d) {
    return o.xf.point(s.center() + d * s.radius());
}

std::uint8_t unit_byte(double x) { return to_byte(x); }
double byte_unit(std::uint8_t b) { return b / 255.0; }

}  // namespace

void direction_to_uv(Vec3 d, double& u, double& v) {
    u = std::atan2(d.y, d.x) / (2 * M_PI) + 0.5;
    v = std::acos(std::clamp(d.z, -1.0, 1.0)) / M_PI;
}

Vec3 uv_to_direction(double u, double v) {
    const double phi = (u - 0.5) * 2 * M_PI, theta = v * M_PI;
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

TextureMaps::Sample TextureMaps::lookup(Vec3 d) const {
    double u, v;
    direction_to_uv(d, u, v);
    const double x = u * width - 0.5, y = std::clamp(v * height - 0.5, 0.0, height - 1.0);
    const int i0 = static_cast<int>(std::floor(x)), j0 = static_cast<int>(std::floor(y));
    const double fx = x - i0, fy = y - j0;
    Sample s{{}, 0, {}};
    for (int dj = 0; dj <= 1; ++dj)
        for (int di = 0; di <= 1; ++di) {
            const int i = ((i0 + di) % width + width) % width, j = std::min(height - 1, j0 + dj);
            const double wgt = (di ? fx : 1 - fx) * (dj ? fy : 1 - fy);
            const std::size_t t = static_cast<std::size_t>(j) * width + i;
            const std::uint8_t* c = &colour_coverage[4 * t];
            const std::uint8_t* n = &normal[3 * t];
            // Colour weighted by coverage, so that bare texels do not darken the fur's edge.
            const double cov = byte_unit(c[3]);
            s.colour += wgt * cov * Vec3{byte_unit(c[0]), byte_unit(c[1]), byte_unit(c[2])};
            s.coverage += wgt * cov;
            s.normal += wgt * Vec3{2 * byte_unit(n[0]) - 1, 2 * byte_unit(n[1]) - 1, 2 * byte_unit(n[2]) - 1};
        }
    if (s.coverage > 0) s.colour = s.colour / s.coverage;
    s.normal = length_squared(s.normal) > 0 ? normalize(s.normal) : d;
    return s;
}

std::size_t texture_base(const Scene& scene) {
    const std::vector<std::size_t> inst = instance_objects(scene);
    if (inst.empty()) return 0;
    // The sphere or ellipsoid nearest the roots, on average.
    double best = kInfinity;
    std::size_t base = scene.objects.size();
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const SphereShape* s = as_sphere(scene.objects[i]);
        if (!s) continue;
        double sum = 0;
        for (const std::size_t k : inst) {
            const SceneObject& o = scene.objects[k];
            const Vec3 root = o.xf.point(primitive_root(scene.primitives[static_cast<std::size_t>(o.primitive)]));
            const Vec3 d = normalize(scene.objects[i].xf.inverse_point(root) - s->center());
            sum += length(surface_point(scene.objects[i], *s, d) - root);
        }
        if (sum < best) {
            best = sum;
            base = i;
        }
    }
    if (base == scene.objects.size())
        throw InputError(located_message(scene.file, scene.objects[inst.front()].where,
                                         "texture mode maps instances onto the sphere or ellipsoid they "
                                         "grow from, and the scene has none"));
    return base;
}

TextureMaps bake_texture(const Scene& scene, const TextureOptions& opt) {
    TextureMaps maps;
    const std::vector<std::size_t> inst = instance_objects(scene);
    if (inst.empty()) return maps;

    maps.base_object = texture_base(scene);
    double tallest = 0;
    std::map<std::uint32_t, int> material_count;
    for (const std::size_t k : inst) {
        const SceneObject& o = scene.objects[k];
        ++material_count[o.material];
        const Bounds3 b = o.xf.bounds(scene.primitives[static_cast<std::size_t>(o.primitive)].shape->bounds());
        tallest = std::max(tallest, length(b.extent()));
    }
    maps.fur_material = std::max_element(material_count.begin(), material_count.end(),
                                         [](const auto& a, const auto& b) { return a.second < b.second; })
                            ->first;

    const SceneObject& base = scene.objects[maps.base_object];
    const SphereShape& sphere = *as_sphere(base);
    const Scene fur = instance_scene(scene);
    const RenderScene rs(fur);
    maps.width = std::max(2, opt.width);
    maps.height = std::max(1, maps.width / 2);
    const int n = std::max(1, opt.subsamples);
    maps.colour_coverage.assign(static_cast<std::size_t>(maps.width) * maps.height * 4, 0);
    maps.normal.assign(static_cast<std::size_t>(maps.width) * maps.height * 3, 0);
    const double above = tallest * 1.01;
    ProgressBar bar("bake", static_cast<std::uint64_t>(maps.height), opt.progress);
    tbb::parallel_for(tbb::blocked_range<int>(0, maps.height, 1), [&](const tbb::blocked_range<int>& rows) {
        for (int j = rows.begin(); j != rows.end(); ++j) {
            for (int i = 0; i < maps.width; ++i) {
                Vec3 colour, normal;
                int hits = 0;
                for (int b = 0; b < n; ++b)
                    for (int a = 0; a < n; ++a) {
                        const Vec3 d = uv_to_direction((i + (a + 0.5) / n) / maps.width,
                                                       (j + (b + 0.5) / n) / maps.height);
                        const Vec3 p = surface_point(base, sphere, d);
                        const Vec3 up = normalize(base.xf.normal(d));
                        SurfaceHit hit;
                        if (!rs.intersect({p + up * above, -up}, 0.0, above, hit)) continue;
                        ++hits;
                        colour += scene.materials[hit.material].color;
                        const Vec3 nw = dot(hit.n, up) < 0 ? -hit.n : hit.n;
                        normal += normalize(transpose(base.xf.forward().m) * nw);  // to object space
                    }
                const std::size_t t = static_cast<std::size_t>(j) * maps.width + i;
                const Vec3 c = hits ? colour / hits : Vec3{};
                const Vec3 nn = hits && length_squared(normal) > 0
                                    ? normalize(normal)
                                    : uv_to_direction((i + 0.5) / maps.width, (j + 0.5) / maps.height);
                for (std::size_t ch = 0; ch < 3; ++ch) {
                    maps.colour_coverage[4 * t + ch] = unit_byte(c[ch]);
                    maps.normal[3 * t + ch] = unit_byte((nn[ch] + 1) / 2);
                }
                maps.colour_coverage[4 * t + 3] = unit_byte(static_cast<double>(hits) / (n * n));
            }
            bar.add(1);
        }
    });
    bar.finish();
    return maps;
}

RenderOutput render_texture(const Scene& scene, const TextureMaps& maps, const RenderOptions& opt) {
    const Scene base_only = base_scene(scene);
    const RenderScene rs(base_only);
    if (maps.width == 0) return render_image(rs, opt);
    // The base's index among the remaining objects: instances before it were removed.
    std::uint32_t base_index = 0;
    for (std::size_t i = 0; i < maps.base_object; ++i)
        if (scene.objects[i].primitive < 0) ++base_index;
    const SceneObject& base = scene.objects[maps.base_object];
    const SphereShape& sphere = dynamic_cast<const SphereShape&>(*base.shape);
    const Material& fur = scene.materials[maps.fur_material];

    RenderOptions o = opt;
    o.shader = [&](const Ray& ray, const SurfaceHit& hit, ShadeCounters& counters) {
        if (hit.object != base_index) return shade(rs, ray, hit, counters);
        const Material& m = scene.materials[hit.material];
        const Vec3 d = normalize(base.xf.inverse_point(hit.p) - sphere.center());
        const TextureMaps::Sample t = maps.lookup(d);
        const Vec3 v = normalize(-ray.d);
        const Vec3 n = dot(hit.n, v) < 0 ? -hit.n : hit.n;
        Vec3 nf = normalize(base.xf.normal(t.normal));
        if (dot(nf, v) < 0) nf = -nf;
        Vec3 bare = m.ka * m.color * scene.ambient, furred = fur.ka * t.colour * scene.ambient;
        auto visible = [&](const Ray& r, double tmin, double tmax, double) {
            return rs.occluded(r, tmin, tmax, hit.object) ? 0.0 : 1.0;
        };
        for_each_light(rs, hit.p, counters, visible, [&](const PointLight& light, Vec3 l, double) {
            bare += phong_term(m, m.color, n, l, v, light.intensity);
            furred += phong_term(fur, t.colour, nf, l, v, light.intensity);
        });
        return (1 - t.coverage) * bare + t.coverage * furred;
    };
    return render_image(rs, o);
}

}  // namespace lat
