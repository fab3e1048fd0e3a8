#include "render/modes/integrators.h"

#include "render/core/camera.h"
#include "render/layers.h"

namespace lat {

Vec3 ExactIntegrator::radiance(const TraceRay& traced, ShadeState& state) const {
    const Ray ray = traced.line();
    SurfaceHit hit;
    if (!rs_.intersect(ray, 0.0, kInfinity, hit)) return rs_.scene().background;
    return shade(rs_, ray, hit, state);
}

Vec3 LayeredIntegrator::radiance(const TraceRay& ray, ShadeState& state) const {
    return trace_layers(rs_, ray, state, maps_);
}

RenderOutput render_exact(const TracedScene& rs, const RenderOptions& opt) {
    return render_image(rs.scene().camera, ExactIntegrator(rs), opt);
}

RenderOutput render_layered(const TracedScene& rs, const RenderOptions& opt,
                            const InstanceShadows* maps) {
    return render_image(rs.scene().camera, LayeredIntegrator(rs, maps), opt);
}

}  // namespace lat
