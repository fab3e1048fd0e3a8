#pragma once
// What the tile loop (render/core/renderer.h) asks of a render mode: the radiance along one
// camera ray. A mode makes its integrator once per render (render/modes/integrators.h, and the
// texture baseline's own), so the tile loop never asks which mode it is in.
#include "render/core/camera.h"
#include "render/core/shading.h"

namespace lat {

class Integrator {
public:
    virtual ~Integrator() = default;
    // Radiance (linear, unclamped) along a camera ray, with its footprint (the camera makes
    // both). `state` is the calling thread's, kept from sample to sample of a tile; the
    // integrator itself is shared by all threads.
    virtual Vec3 radiance(const TraceRay& ray, ShadeState& state) const = 0;
};

}  // namespace lat
