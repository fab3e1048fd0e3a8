#pragma once
// Phong shading with shadows, exactly as the reference format states it (docs/scene-format.md).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "render/core/traced_scene.h"

namespace lat {

// What the shading of a run of samples (a tile's, one thread's) keeps from sample to sample:
// the shadow rays cast, and per light what blocked its last shadow ray (EmbreeAccel::
// LastBlocker), tested first by the next (lights past kKeptBlockers keep none).
struct ShadeState {
    std::uint64_t shadow_rays = 0;
    static constexpr std::size_t kKeptBlockers = 8;
    std::array<EmbreeAccel::LastBlocker, kKeptBlockers> last_blocker;
    EmbreeAccel::LastBlocker* kept_blocker(std::size_t light) {
        return light < kKeptBlockers ? &last_blocker[light] : nullptr;
    }
};

// One light's Phong term (diffuse + specular, before shadowing) at a surface of colour `color`
// and material m, unit normal n facing the viewer, unit direction l to the light and v to the
// viewer. The one home of the reflection rule: exact and lattice shading, and the texture
// mode's baked surfaces, all use it.
// normal_length: below 1, n stands for unit normals spread around it whose mean is that long
// (prefiltered lattices' tables, SurfaceHit::normal_length; a sheet of sub-rays has its own
// normals, SurfaceHit::normals, and shade_with takes the mean of their exact terms instead,
// which is closer to exact than this model). The diffuse term is the mean of the normals'
// clamped terms max(0, n_i.l), not the clamped term of their mean, which is too dark where the
// normals straddle the terminator: n_i.l is taken as normal with mean len n.l and variance
// (1 - len^2) / 3 (the variance of a spread of unit vectors with mean length len, whatever the
// direction, for a spread symmetric about its mean), whose clamped mean is closed-form
// (diffuse_mean). The specular lobe is widened as Toksvig's filtering of normal maps widens it
// ("Mipmapping normal maps", 2005): for a mean normal of length len the exponent s becomes
// s' = len s / (len + s (1 - len)), and the lobe is scaled by (s' + 1) / (s + 1) so that the
// light it reflects stays the same (the integral of cos^s over the sphere is 2 pi / (s + 1)).
// len is normal_length^kToksvigWidening: the lobe is widened more than the mean's length
// alone says. k = 3 is the best of 1, 2, 3, 6 and 10 on Plates 2 and 4 and grass, and within
// 0.1 dB of the best at a million hairs (bench/notes/shading-constants.md).
inline constexpr double kToksvigWidening = 3;
// E[max(0, X)] for X normal with mean len * nl and variance (1 - len^2) / 3 (see phong_term).
inline double diffuse_mean(double nl, double len) {
    const double mean = len * nl, sd = std::sqrt((1 - len * len) / 3);
    if (sd < 1e-9) return std::max(0.0, mean);
    const double z = mean / sd;
    return sd * std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI) + mean * 0.5 * std::erfc(-z / std::sqrt(2.0));
}
inline Vec3 phong_term(const Material& m, Vec3 color, Vec3 n, Vec3 l, Vec3 v, Vec3 intensity,
                       double normal_length = 1) {
    const double nl = dot(n, l);
    const Vec3 r = 2 * nl * n - l;
    const double rv = std::max(0.0, dot(r, v));
    double spec, diffuse = m.kd * std::max(0.0, nl);
    if (normal_length < 1) {
        const double len = std::pow(normal_length, kToksvigWidening), s = m.shininess;
        diffuse = m.kd * diffuse_mean(nl, normal_length);
        const double s1 = len * s / (len + s * (1 - len));
        spec = m.ks * (s1 + 1) / (s + 1) * std::pow(rv, s1);
    } else {
        spec = m.ks * std::pow(rv, m.shininess);
    }
    return intensity * (diffuse * color + Vec3{spec, spec, spec});
}

// Radiance (linear, unclamped) seen along `ray` at `hit`.
Vec3 shade(const TracedScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeState& state);

// Start of shadow rays: far enough from the surface to skip its own crossing, which double
// precision places within ~1e-12 relative of the true one, and small against any feature.
double shadow_epsilon(Vec3 p);

// The lights that reach p, each with its shadow ray cast (when the scene has shadows):
// term(light, unit direction to it) is the light's contribution unshadowed, a value that
// compares equal to its default (zero) when the light adds nothing; visible(light's index,
// shadow ray, tmin, tmax, distance, term) gives the share of the light that arrives (the term
// tells it how precisely that matters), and lit(term, share) is called when that is above 0.
// A light whose term is zero casts no shadow ray: shadowed or not, it adds nothing, and the
// image is the same. With a unit normal that is a surface turned from the light, N.L and R.V
// both at most 0 (6 to 9 % of the shadow rays of the ball scenes and grass); a prefiltered
// lattice's mean normal spreads its diffuse term past the terminator, so its layers rarely
// skip one. The one home of the light loop: shade(),
// layered shading, the texture mode's baked surfaces and particle mode (whose visibility reads
// a shadow map per light) go through it.
template <class Term, class Visible, class Lit>
void for_each_light(const TracedScene& rs, Vec3 p, ShadeState& state, Term&& term,
                    Visible&& visible, Lit&& lit) {
    const Scene& s = rs.scene();
    const double eps = shadow_epsilon(p);
    for (std::size_t i = 0; i < s.lights.size(); ++i) {
        const PointLight& light = s.lights[i];
        const Vec3 to_light = light.position - p;
        const double dist = length(to_light);
        if (dist == 0) continue;
        const Vec3 l = to_light / dist;
        const auto unshadowed = term(light, l);
        if (unshadowed == decltype(unshadowed){}) continue;
        double seen = 1;
        if (s.shadows) {
            ++state.shadow_rays;
            seen = visible(i, Ray{p, l}, eps, dist * (1 - 1e-12), dist, unshadowed);
            if (seen <= 0) continue;
        }
        lit(unshadowed, seen);
    }
}

// visible for for_each_light and shade_with where nothing is partly covered: the light
// arrives whole (1) unless the shadow ray, leaving object self, meets something (0).
inline auto hard_shadows(const TracedScene& rs, std::uint32_t self, ShadeState& state) {
    return [&rs, self, &state](std::size_t light, const Ray& r, double tmin, double tmax, double,
                               const auto&) {
        return rs.occluded(r, tmin, tmax, self, state.kept_blocker(light)) ? 0.0 : 1.0;
    };
}

// Phong with shadows; visible(light's index, shadow ray, tmin, tmax, distance, term) is the
// share of the light that arrives: 0 or 1 for shade(), a transmittance through partial hits for layered
// rays (render/layers.h), a shadow map's for particle mode's base.
template <class Visible>
Vec3 shade_with(const TracedScene& rs, const Ray& ray, const SurfaceHit& hit, ShadeState& state,
                Visible&& visible) {
    const Scene& s = rs.scene();
    const Material& m = s.materials[hit.material];
    const Vec3 v = normalize(-ray.d);
    const auto facing = [&](Vec3 x) { return dot(x, v) < 0 ? -x : x; };  // the viewer's side
    const Vec3 n = facing(hit.n);

    Vec3 c = m.ka * m.color * s.ambient;
    const auto term = [&](const PointLight& light, Vec3 l) {
        if (hit.normals.count == 0)
            return phong_term(m, m.color, n, l, v, light.intensity, hit.normal_length);
        Vec3 sum;
        for (std::uint8_t k = 0; k < hit.normals.count; ++k) {
            sum += phong_term(m, m.color, facing(hit.normals.n[k]), l, v, light.intensity);
        }
        return sum / double(hit.normals.count);
    };
    const auto lit = [&](Vec3 added, double seen) {
        c += seen == 1 ? added : added * seen;
    };
    for_each_light(rs, hit.p, state, term, visible, lit);
    return c;
}

}  // namespace lat
