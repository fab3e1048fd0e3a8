#pragma once
// The policy of tracing through partial coverage. A prefiltered lattice answers a ray with a
// sheet of coverage alpha < 1, so a camera ray is traced front to back: each surface met adds
// alpha of its shade, weighted by what is still uncovered, and the ray goes on behind it.
// Shadow rays likewise get the transmittance of what they cross instead of a yes/no. What is
// left of a ray is composed by LayerComposite: sheets of sub-rays block each sub-ray once, the
// tables' sheets are independent draws (the product of 1 - alpha). Exact shapes have alpha = 1,
// so a scene without lattices shades as it would without layers. The renderer shades
// (render/layers.h); the accelerator collects (coverage/layer_sink.h); this file decides.
#include <algorithm>
#include <span>

#include "coverage/layer_composite.h"
#include "coverage/layer_sink.h"
#include "math/vec.h"

namespace lat {

// Partial surfaces without sub-rays (the tables') composited along a camera ray, at most: the
// last one is taken as opaque. A pixel's share left behind eight sheets of coverage 1/2 is
// 1/256, under an 8-bit step; deeper stacks of partial sheets are rare (the edges of
// overlapping hairs). Sheets of sub-rays are not counted: at most 4 of them add something, and
// once all 4 sub-rays are blocked the ray ends. One traversal finds them all.
inline constexpr int kMaxLayers = 8;
// Below this share left uncovered, the rest of a ray is not traced.
inline constexpr double kMinTransmittance = 1.0 / 1024;

// A shadow ray's footprint leaving a surface is at most this many times the camera ray's there
// (and at least its inverse): the pixel's footprint on the surface seen from the light.
inline constexpr double kMaxShadowWidening = 4;

// How far a camera ray's traversal looks.
inline LayerStop camera_stop() { return {.max_layers = kMaxLayers, .min_left = kMinTransmittance}; }
// A shadow ray's worth: the most it can add to its pixel, its layer's share of the pixel times
// the light's unshadowed term (its largest channel, in display units: images are linear, an
// 8-bit step is 1/255). It counts as blocked once what it would still add falls under this,
// a quarter of a step: a layer deep behind partial sheets, or lit faintly, needs its shadow
// ray traced only as far as a front layer's needs it traced to kMinTransmittance.
inline constexpr double kMinShadowContribution = 1.0 / 1024;
inline LayerStop shadow_stop(double worth) {
    const double below = kMinShadowContribution / std::max(worth, kMinShadowContribution);
    return {.blocked_below = std::max(kMinTransmittance, below)};
}

// The width of a shadow ray's footprint as it leaves a surface of unit normal n, seen along
// camera_d with a footprint `width` wide, towards shadow_d.
double shadow_width(Vec3 n, Vec3 camera_d, Vec3 shadow_d, double width);

// How far a shadow ray towards shadow_d stays within the camera footprint, `width` wide, of
// the surface it leaves, seen along camera_d from `distance` away (RayFootprint::seen_until):
// until its offset from the camera's line reaches the footprint's half-width, which narrows
// towards the eye. 0 when it leaves on the far side, away from the eye.
double seen_until(Vec3 camera_d, Vec3 shadow_d, double width, double distance);

// The footprint's width at a layer of this coverage and these sub-rays, `width` the ray's
// there.
double sheet_width(double alpha, std::uint8_t sub_rays, double width);

// The share of light a shadow ray's partial crossings let through (the ray not blocked), 0 once
// it is below kMinTransmittance.
double transmitted(std::span<const ObjectHit> partial);

// A camera ray's colour from its partial layers in ray order (each with `alpha` and `sub_rays`,
// shaded by shade(h, weight), weight its share of the colour) and what lies behind them
// (behind(weight), asked only if the layers let something through to it).
template <class Hit, class Shade, class Behind>
Vec3 composite_layers(std::span<const Hit> partial, Shade&& shade, Behind&& behind) {
    Vec3 c;
    LayerComposite seen;
    for (const Hit& h : partial) {
        const double left = seen.left();
        // A layer whose sub-rays were all blocked in front of it adds nothing (not shaded);
        // the last one counted (the traversal looked no farther) is taken as opaque.
        double alpha = seen.add(h.alpha, h.sub_rays);
        const bool last = h.sub_rays == 0 && seen.draws() == kMaxLayers;
        if (last) alpha = 1;
        if (alpha > 0) c += shade(h, left * alpha) * (left * alpha);
        if (last || seen.left() <= kMinTransmittance) return c;
    }
    return c + behind(seen.left()) * seen.left();
}

}  // namespace lat
