#pragma once
// Shading through partial coverage: a camera ray's layers, shaded front to back, and a shadow
// ray's transmittance, as the policy in coverage/layers.h has them.
#include "coverage/layers.h"
#include "render/core/camera.h"
#include "render/core/traced_scene.h"
#include "render/core/shading.h"

namespace lat {

class InstanceShadows;

// Radiance along a camera ray, whose footprint picks the lattices' levels of detail and spans
// their sub-rays. maps: where given, the shadows its instances cast on lights it maps
// (render/instance_shadows.h); else shadow rays through everything.
Vec3 trace_layers(const TracedScene& rs, const TraceRay& ray, ShadeState& state,
                  const InstanceShadows* maps = nullptr);

// The share of light that gets through from tmin to tmax along r (a shadow ray's
// TraceRay::ray()) leaving a surface of object `self`,
// whose crossings within its surface tolerance are skipped. last: what blocked the last ray of
// its run, if kept (EmbreeAccel::LastBlocker). worth: the most the light can add to the pixel
// (shadow_stop); 1 traces the ray until under kMinTransmittance gets through.
double transmittance(const TracedScene& rs, const Ray& r, double tmin, double tmax,
                     std::uint32_t self, EmbreeAccel::LastBlocker* last = nullptr,
                     double worth = 1);

}  // namespace lat
