#include "render/layers.h"

#include <algorithm>
#include <cmath>

#include "geometry/sub_rays.h"

namespace lat {
namespace {

// The width of a shadow ray's footprint as it leaves a surface: the pixel's footprint on the
// surface, width / cos_v long across and width wide (cos_v: the camera ray's cosine with the
// normal n), seen from the light (times cos_l) is an ellipse of area width^2 cos_l / cos_v; the
// isotropic filter of a lattice's level gets the width of the same area, within 1/4 to 4
// times the camera's (kMaxShadowWidening; a surface seen edge-on). Fur scenes: +0.0 to
// +0.25 dB against the camera's width (the floor and the sphere seen at a slant, the hairs'
// sides).
double shadow_width(const Ray& ray, const SurfaceHit& hit, const Ray& shadow, double width) {
    const double cv = std::max(1.0 / 16, std::abs(dot(hit.n, ray.d)) / length(ray.d));
    const double cl = std::abs(dot(hit.n, shadow.d)) / length(shadow.d);
    return width * std::clamp(std::sqrt(cl / cv), 1 / kMaxShadowWidening, kMaxShadowWidening);
}

// The footprint's width at a layer, `width` the ray's there: a sheet of sub-rays covers the
// share of the footprint its coverage says (Shape::sheets), and its shadow rays' footprint is
// as wide as that share's area (ball-tuft216 +0.12 dB, tuft200 +0.08, the furry bunny +0.05;
// Plates 4 and 5 +0.01 and +0.03).
double sheet_width(const SurfaceHit& h, double width) {
    return h.sub_rays == 0 ? width : width * std::sqrt(h.alpha);
}

// Radiance at a layer; `width`: its footprint (world units), which picks the lattices' levels
// of detail for its shadow rays, narrowing to the point light.
Vec3 shade_layer(const RenderScene& rs, const Ray& ray, const SurfaceHit& hit, double width,
                 ShadeState& state) {
    const auto visible = [&](std::size_t light, const Ray& r, double tmin, double tmax,
                             double dist) {
        // Narrowing to the light; sub-rays along the same world directions in every lattice
        // (geometry/sub_rays.h).
        const double w = shadow_width(ray, hit, r, width);
        const RayFootprint f = footprint_across(normalize(r.d), w, -w / dist, true);
        return transmittance(rs, {r.o, r.d, &f}, tmin, tmax, hit.object, state.kept_blocker(light));
    };
    return shade_with(rs, ray, hit, state, visible);
}

}  // namespace

double transmittance(const RenderScene& rs, const Ray& r, double tmin, double tmax,
                     std::uint32_t self, EmbreeAccel::LastBlocker* last) {
    thread_local std::vector<AccelHit> partial;
    const LayerStop stop{.blocked_below = kMinTransmittance};
    if (rs.partial_crossings(r, tmin, tmax, self, partial, stop, last))
        return 0;
    LayerComposite through;
    for (const AccelHit& h : partial) through.add(h.crossing);
    const double trans = through.left();
    return trans <= kMinTransmittance ? 0 : trans;
}

Vec3 trace_layers(const RenderScene& rs, const Ray& ray, double spread, ShadeState& state) {
    thread_local std::vector<SurfaceHit> partial;
    // Sub-rays along the same world directions in every lattice (geometry/sub_rays.h).
    const RayFootprint f = footprint_across(normalize(ray.d), 0, spread, false);
    SurfaceHit opaque;
    const bool found =
        rs.intersect_layers({ray.o, ray.d, &f}, 0.0, kInfinity, EmbreeAccel::kNoObject, opaque,
                            partial, {.max_layers = kMaxLayers, .min_left = kMinTransmittance});
    // Shading moves the footprint (shadow rays): the layers are all found first. (Shadow rays
    // leave `partial` as it is: transmittance has its own.)
    Vec3 c;
    LayerComposite seen;
    for (const SurfaceHit& h : partial) {
        const double left = seen.left();
        // A layer whose sub-rays were all blocked in front of it adds nothing (not shaded);
        // the last one counted (the traversal looked no farther) is taken as opaque.
        double alpha = seen.add(h.alpha, h.sub_rays);
        const bool last = h.sub_rays == 0 && seen.draws() == kMaxLayers;
        if (last) alpha = 1;
        if (alpha > 0)
            c += shade_layer(rs, ray, h, sheet_width(h, spread * h.t), state) * (left * alpha);
        if (last || seen.left() <= kMinTransmittance) return c;
    }
    return c + (found ? shade_layer(rs, ray, opaque, spread * opaque.t, state)
                      : rs.scene().background) * seen.left();
}

}  // namespace lat
