#pragma once
// Shadows cast by a scene's instances read from deep shadow maps, one per light
// (render/deep_shadow_map.h), and shadows cast by everything else from shadow rays against the
// scene without its instances (its base): among fur, a shadow ray through the instances' tables
// visits tens of them, a map lookup four texels.
#include <cstdint>
#include <memory>
#include <vector>

#include "render/core/traced_scene.h"
#include "render/deep_shadow_map.h"

namespace lat {

// What a render's maps came to, once it has traced what it needed: lights mapped, texels a
// side of each light's map (0: none), their tiles and those traced (DeepShadowMap::kTile),
// knots and bytes.
struct ShadowMapReport {
    std::size_t lights = 0, lights_mapped = 0;
    std::vector<int> sizes;
    std::uint64_t tiles = 0, tiles_traced = 0, bytes = 0, knots = 0;
};

class InstanceShadows {
public:
    // The maps of rs's instances, lying in `target` (instance_bounds), traced as rs traces them;
    // and the base, traced with the same instance shapes (a CSG of instances, part of the base,
    // keeps its lattices). Each map is `size` texels a side, or with size 0 as many as make a
    // texel at the instances' centre as wide as a camera sample's footprint there (`spread`: its
    // width per unit distance, PinholeCamera::spread), within kMinSize to kMaxSize. A light
    // within the instances' bounding sphere gets no map: its shadow rays go through the
    // instances as without maps. The maps take at most max_bytes together (MapBudget).
    InstanceShadows(const TracedScene& rs, const Bounds3& target,
                    const TracedScene::InstanceShapeFn& instance_shape, const AccelOptions& accel,
                    int size, double spread, std::uint64_t max_bytes = kMaxBytes);
    ~InstanceShadows();

    static constexpr int kMinSize = 64, kMaxSize = 4096;
    static constexpr std::uint64_t kMaxBytes = std::uint64_t{2} << 30;

    bool mapped(std::size_t light) const { return maps_[light].valid(); }
    // The share of light `light` (mapped) reaching the start of shadow ray r (tmin to tmax, as
    // for_each_light gives it) on a surface of rs's object `self` whose footprint there is
    // `width` wide: the base's transmittance times the map's.
    double visible(std::size_t light, const Ray& r, double tmin, double tmax, std::uint32_t self,
                   double width, EmbreeAccel::LastBlocker* last) const;

    ShadowMapReport report() const;

private:
    std::unique_ptr<Scene> base_scene_;
    std::unique_ptr<TracedScene> base_;
    std::vector<std::uint32_t> base_object_;  // rs's object -> base's (kNoObject: an instance)
    std::unique_ptr<MapBudget> budget_;
    std::vector<DeepShadowMap> maps_;
};

// The world bounds of a scene's instances as rs traces them.
Bounds3 instance_bounds(const TracedScene& rs);

}  // namespace lat
