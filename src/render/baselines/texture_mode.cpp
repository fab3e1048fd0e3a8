#include "render/baselines/texture_mode.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "render/core/traced_scene.h"
#include "render/baselines/scene_parts.h"
#include "render/core/shading.h"
#include "scene/scatter.h"
#include "util/error.h"
#include "util/progress.h"

namespace lat {
namespace {

std::uint8_t unit_byte(double x) { return to_byte(x); }
double byte_unit(std::uint8_t b) { return b / 255.0; }

// The distance from `root` to the nearest crossing of o's surface with the line through it
// along unit `up` (world units), or infinity. The rays start `slack` back, so a crossing at the
// root itself is not lost to rounding.
double distance_along(const SceneObject& o, Vec3 root, Vec3 up, double slack) {
    double best = kInfinity;
    for (const double s : {1.0, -1.0}) {
        Crossing c;
        const Ray r = o.xf.inverse_ray({root - s * slack * up, s * up});
        if (o.shape->intersect(r, 0.0, kInfinity, c)) best = std::min(best, std::abs(c.t - slack));
    }
    return best;
}

double instance_size(const Scene& scene, const SceneObject& o) {
    return length(o.xf.bounds(scene.primitives[static_cast<std::size_t>(o.primitive)].shape->bounds()).extent());
}

// How far instance o's root lies from base's surface, along o's up axis (or infinity).
double root_distance(const Scene& scene, const SceneObject& base, const SceneObject& o) {
    const Vec3 root = o.xf.point(primitive_root(scene.primitives[static_cast<std::size_t>(o.primitive)]));
    return distance_along(base, root, normalize(o.xf.vector({0, 0, 1})), 1e-3 * instance_size(scene, o));
}

// Object space from world normals (the transpose of the forward map), unit.
Vec3 to_object_normal(const SceneObject& o, Vec3 n) { return normalize(transpose(o.xf.forward().m) * n); }

}  // namespace

TextureMaps::Sample TextureMaps::lookup(Vec3 p, std::uint32_t part, Vec3 geometric) const {
    const TexelWeights tw = atlas->lookup(p, part);
    Sample s{{}, 0, {}};
    for (int k = 0; k < tw.count; ++k) {
        const double wgt = tw.weight[static_cast<std::size_t>(k)];
        const std::size_t t = tw.texel[static_cast<std::size_t>(k)];
        const std::uint8_t* c = &colour_coverage[4 * t];
        const std::uint8_t* n = &normal[3 * t];
        // Colour weighted by coverage, so that bare texels do not darken the fur's edge.
        const double cov = byte_unit(c[3]);
        s.colour += wgt * cov * Vec3{byte_unit(c[0]), byte_unit(c[1]), byte_unit(c[2])};
        s.coverage += wgt * cov;
        s.normal += wgt * Vec3{2 * byte_unit(n[0]) - 1, 2 * byte_unit(n[1]) - 1, 2 * byte_unit(n[2]) - 1};
    }
    if (s.coverage > 0) s.colour = s.colour / s.coverage;
    s.normal = length_squared(s.normal) > 0 ? normalize(s.normal) : geometric;
    return s;
}

std::size_t texture_base(const Scene& scene) {
    const std::vector<std::size_t> inst = instance_objects(scene);
    if (inst.empty()) return 0;
    constexpr std::size_t kProbes = 1024;
    const std::size_t step = std::max<std::size_t>(1, inst.size() / kProbes);
    std::size_t base = scene.objects.size();
    double best = kInfinity;
    std::vector<double> d;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const SceneObject& candidate = scene.objects[i];
        if (candidate.primitive >= 0) continue;
        d.clear();
        for (std::size_t k = 0; k < inst.size(); k += step)
            d.push_back(root_distance(scene, candidate, scene.object(inst[k])));
        std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
        if (d[d.size() / 2] < best) {
            best = d[d.size() / 2];
            base = i;
        }
    }
    if (base == scene.objects.size())
        throw InputError(located_message(scene.file, scene.where_of(inst.front()),
                                         "texture mode maps instances onto the surface they grow from, and no "
                                         "object of the scene lies under their roots"));
    if (!has_texture_atlas(scene.objects[base]))
        throw InputError(located_message(scene.file, scene.objects[base].where,
                                         "the instances grow from this object, and texture mode maps onto "
                                         "spheres, ellipsoids and triangle meshes only"));
    // All of them: fur standing elsewhere would be baked as seen from this surface, wrongly.
    for (const std::size_t k : inst) {
        const SceneObject o = scene.object(k);
        if (root_distance(scene, scene.objects[base], o) > instance_size(scene, o))
            throw InputError(located_message(
                scene.file, o.where,
                "texture mode maps every instance onto the one surface most of them grow from, " +
                    scene.objects[base].where + ", and this one stands apart from it"));
    }
    return base;
}

TextureMaps bake_texture(const Scene& scene, const TextureOptions& opt) {
    TextureMaps maps;
    const std::vector<std::size_t> inst = instance_objects(scene);
    if (inst.empty()) return maps;

    maps.base_object = texture_base(scene);
    const SceneObject& base = scene.objects[maps.base_object];
    // How far above the base the fur reaches: each instance's root's distance from it plus
    // the instance's size.
    double reach = 0;
    std::map<std::uint32_t, int> material_count;
    for (const std::size_t k : inst) {
        const SceneObject o = scene.object(k);
        ++material_count[o.material];
        const double d = root_distance(scene, base, o);
        reach = std::max(reach, instance_size(scene, o) + (std::isfinite(d) ? d : 0.0));
    }
    maps.fur_material = std::max_element(material_count.begin(), material_count.end(),
                                         [](const auto& a, const auto& b) { return a.second < b.second; })
                            ->first;

    maps.atlas = make_texture_atlas(base, opt.width);
    const TextureAtlas& atlas = *maps.atlas;
    const Scene fur = instance_scene(scene);
    const TracedScene rs(fur);
    const int n = std::max(1, opt.subsamples);
    const std::size_t texels = atlas.texel_count();
    maps.colour_coverage.assign(texels * 4, 0);
    maps.normal.assign(texels * 3, 0);
    const double above = reach * 1.01;
    constexpr std::size_t kGrain = 4096;
    ProgressBar bar("bake", (texels + kGrain - 1) / kGrain, opt.progress);
    using Range = tbb::blocked_range<std::size_t>;
    tbb::parallel_for(Range(0, texels, kGrain), [&](const Range& r) {
        for (std::size_t t = r.begin(); t != r.end(); ++t) {
            Vec3 colour, normal;
            int hits = 0, samples = 0;
            for (int b = 0; b < n; ++b)
                for (int a = 0; a < n; ++a) {
                    SurfacePoint s;
                    if (!atlas.texel_point(t, (a + 0.5) / n, (b + 0.5) / n, s)) continue;
                    ++samples;
                    const Vec3 p = base.xf.point(s.p), up = normalize(base.xf.normal(s.n));
                    // Only the fur between the sample and the base where it folds back over it.
                    double top = above;
                    Crossing fold;
                    if (base.shape->intersect(base.xf.inverse_ray({p, up}), 1e-4 * above, above, fold))
                        top = fold.t;
                    SurfaceHit hit;
                    if (!rs.intersect({p + up * top, -up}, 0.0, top, hit)) continue;
                    ++hits;
                    colour += scene.materials[hit.material].color;
                    normal += to_object_normal(base, dot(hit.n, up) < 0 ? -hit.n : hit.n);
                }
            SurfacePoint centre;
            if (!atlas.texel_point(t, 1.0 / 3, 1.0 / 3, centre)) centre.n = {0, 0, 1};  // always on
            const Vec3 c = hits ? colour / hits : Vec3{};
            const Vec3 nn = hits && length_squared(normal) > 0 ? normalize(normal) : centre.n;
            for (std::size_t ch = 0; ch < 3; ++ch) {
                maps.colour_coverage[4 * t + ch] = unit_byte(c[ch]);
                maps.normal[3 * t + ch] = unit_byte((nn[ch] + 1) / 2);
            }
            maps.colour_coverage[4 * t + 3] = unit_byte(samples ? static_cast<double>(hits) / samples : 0.0);
            if ((t + 1) % kGrain == 0) bar.add(1);
        }
    });
    bar.finish();
    return maps;
}

namespace {

// Exact shading, but at the base surface the bare base and the baked fur blended by coverage.
class TextureIntegrator final : public Integrator {
public:
    TextureIntegrator(const Scene& scene, const TextureMaps& maps, const TracedScene& rs)
        : scene_(scene), maps_(maps), rs_(rs) {
        if (!maps.atlas) return;
        // The base's index among the traced objects: instances before it were removed.
        for (std::size_t i = 0; i < maps.base_object; ++i)
            if (scene.primitive_of(i) < 0) ++base_index_;
    }

    Vec3 radiance(const TraceRay& traced, ShadeState& state) const override {
        const Ray ray = traced.line();
        SurfaceHit hit;
        if (!rs_.intersect(ray, 0.0, kInfinity, hit)) return rs_.scene().background;
        if (!maps_.atlas || hit.object != base_index_) return shade(rs_, ray, hit, state);
        return textured(ray, hit, state);
    }

private:
    const Scene& scene_;  // with its instances
    const TextureMaps& maps_;
    const TracedScene& rs_;  // the scene without them
    std::uint32_t base_index_ = 0;

    Vec3 textured(const Ray& ray, const SurfaceHit& hit, ShadeState& state) const {
        const SceneObject& base = scene_.objects[maps_.base_object];
        const Material& fur = scene_.materials[maps_.fur_material];
        const Material& m = scene_.materials[hit.material];
        const TextureMaps::Sample t =
            maps_.lookup(base.xf.inverse_point(hit.p), hit.part, to_object_normal(base, hit.n));
        const Vec3 v = normalize(-ray.d);
        const Vec3 n = dot(hit.n, v) < 0 ? -hit.n : hit.n;
        Vec3 nf = normalize(base.xf.normal(t.normal));
        if (dot(nf, v) < 0) nf = -nf;
        Vec3 bare = m.ka * m.color * scene_.ambient, furred = fur.ka * t.colour * scene_.ambient;
        const auto visible = hard_shadows(rs_, hit.object, state);
        // Both surfaces' terms: a light that adds to neither casts no shadow ray.
        struct Terms {
            Vec3 bare, furred;
            bool operator==(const Terms&) const = default;
        };
        const auto terms = [&](const PointLight& light, Vec3 l) {
            return Terms{phong_term(m, m.color, n, l, v, light.intensity),
                         phong_term(fur, t.colour, nf, l, v, light.intensity)};
        };
        const auto lit = [&](const Terms& added, double) {
            bare += added.bare;
            furred += added.furred;
        };
        for_each_light(rs_, hit.p, state, terms, visible, lit);
        return (1 - t.coverage) * bare + t.coverage * furred;
    }
};

}  // namespace

RenderOutput render_texture(const Scene& scene, const TextureMaps& maps, const RenderOptions& opt) {
    const Scene base_only = base_scene(scene);
    const TracedScene rs(base_only);
    return render_image(base_only.camera, TextureIntegrator(scene, maps, rs), opt);
}

}  // namespace lat
