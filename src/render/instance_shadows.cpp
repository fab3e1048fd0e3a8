#include "render/instance_shadows.h"

#include <algorithm>
#include <cmath>

#include "render/baselines/scene_parts.h"
#include "render/layers.h"

namespace lat {
namespace {

// How much nearer the light than a point a crossing must lie to shadow it, in footprints (the
// wider of the point's own and the map's texel there): the point's own object is left out, but
// a sheet's blended point lies within about a footprint of its neighbours' crossings, which the
// filtered tables blend into it. The most faithful of those tried on the bunny's fur
// (bench/notes/scale-log.md).
constexpr double kBiasFootprints = 1.5;

// Texels a side for a map from `light` over the sphere around `target` whose texel at its centre
// is as wide as a camera sample's footprint there.
int matched_size(const Camera& camera, Vec3 light, const Bounds3& target, double spread) {
    const MapFrame f = MapFrame::aimed(light, target);
    const double sample = spread * length(target.center() - camera.eye);
    const double texels = f.width_at_centre() / sample;
    if (!f.valid || !std::isfinite(texels)) return InstanceShadows::kMinSize;
    return static_cast<int>(std::clamp(std::ceil(texels), double(InstanceShadows::kMinSize),
                                       double(InstanceShadows::kMaxSize)));
}

}  // namespace

Bounds3 instance_bounds(const TracedScene& rs) {
    const Scene& s = rs.scene();
    Bounds3 b;
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
        const SceneObject& o = s.objects[i];
        if (o.primitive >= 0) b = merge(b, o.xf.bounds(rs.shape(static_cast<std::uint32_t>(i)).bounds()));
    }
    for (const ScatterGroup& g : s.scatters) {
        if (g.count == 0) continue;
        const Bounds3 local = rs.shape(static_cast<std::uint32_t>(g.first)).bounds();
        for (const Affine& a : g.placements)
            for (int c = 0; c < 8; ++c) b = merge(b, a.point(local.corner(c)));
    }
    return b;
}

InstanceShadows::InstanceShadows(const TracedScene& rs, const Bounds3& target,
                                 const TracedScene::InstanceShapeFn& instance_shape,
                                 const AccelOptions& accel, int size, double spread,
                                 std::uint64_t max_bytes)
    : budget_(std::make_unique<MapBudget>(max_bytes)) {
    const Scene& s = rs.scene();
    base_scene_ = std::make_unique<Scene>(base_scene(s));
    AccelOptions quiet = accel;
    quiet.progress = false;
    base_ = std::make_unique<TracedScene>(*base_scene_, instance_shape, quiet);
    base_object_.assign(s.object_count(), EmbreeAccel::kNoObject);
    std::uint32_t next = 0;
    for (std::size_t i = 0; i < s.objects.size(); ++i)
        if (s.objects[i].primitive < 0) base_object_[i] = next++;
    maps_.reserve(s.lights.size());
    for (std::size_t i = 0; i < s.lights.size(); ++i) {
        const Vec3 light = s.lights[i].position;
        maps_.emplace_back(rs, light, target,
                           size > 0 ? size : matched_size(s.camera, light, target, spread),
                           "lights[" + std::to_string(i) + "]", *budget_);
    }
}

InstanceShadows::~InstanceShadows() = default;

double InstanceShadows::visible(std::size_t light, const Ray& r, double tmin, double tmax,
                                std::uint32_t self, double width,
                                EmbreeAccel::LastBlocker* last) const {
    const double base = transmittance(*base_, r, tmin, tmax, base_object_[self], last);
    if (base <= 0) return 0;
    const DeepShadowMap& map = maps_[light];
    const double dist = length(r.o - base_scene_->lights[light].position);
    const double bias = kBiasFootprints * std::max(width, map.texel_width(dist));
    return base * map.transmittance(r.o, bias, self);
}

ShadowMapReport InstanceShadows::report() const {
    ShadowMapReport r;
    r.lights = maps_.size();
    for (const DeepShadowMap& m : maps_) {
        r.sizes.push_back(m.valid() ? m.size() : 0);
        if (!m.valid()) continue;
        ++r.lights_mapped;
        r.tiles += m.tiles();
        r.tiles_traced += m.tiles_traced();
        r.bytes += m.bytes();
        r.knots += m.knots();
    }
    return r;
}

}  // namespace lat
