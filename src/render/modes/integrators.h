#pragma once
// The integrators of the ray-traced modes (render/render_modes.h makes one per render):
// exact point samples, and layers of partial coverage traced front to back. The texture
// baseline has its own (render/baselines/texture_mode.cpp).
#include "render/core/integrator.h"
#include "render/core/traced_scene.h"
#include "render/core/renderer.h"
#include "render/instance_shadows.h"

namespace lat {

// Each ray's closest hit, shaded by the reference Phong rule (shade()), or the background.
class ExactIntegrator final : public Integrator {
public:
    explicit ExactIntegrator(const TracedScene& rs) : rs_(rs) {}
    Vec3 radiance(const TraceRay& ray, ShadeState& state) const override;

private:
    const TracedScene& rs_;
};

// Each ray traced front to back through partial hits (render/layers.h), its footprint (the
// camera's, TraceRay) choosing prefiltered lattices' levels and spanning sub-ray sheets.
// maps: where given, the shadows the instances cast (render/instance_shadows.h).
class LayeredIntegrator final : public Integrator {
public:
    explicit LayeredIntegrator(const TracedScene& rs, const InstanceShadows* maps = nullptr)
        : rs_(rs), maps_(maps) {}
    Vec3 radiance(const TraceRay& ray, ShadeState& state) const override;

private:
    const TracedScene& rs_;
    const InstanceShadows* maps_;
};

// The scene's image through each integrator.
RenderOutput render_exact(const TracedScene& rs, const RenderOptions& opt = {});
RenderOutput render_layered(const TracedScene& rs, const RenderOptions& opt = {},
                            const InstanceShadows* maps = nullptr);

}  // namespace lat
