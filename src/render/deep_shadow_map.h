#pragma once
// Deep shadow maps (Lokovic and Veach, "Deep Shadow Maps", SIGGRAPH 2000) of the instances
// answered through their footprints, one per point light: shadow rays among fur spend most of a
// layered render (each starts inside tens of other hairs' boxes and visits them all), where a
// map answers each in one lookup. The map is traced from the light through the same filtered
// tables a shadow ray reads: one ray per texel, its footprint the texel's, keeping each crossing
// it meets (a knot: its distance from the light, the share of the light it covers, its object).
// A point reads the light that reaches it from the four texels around it: the crossings nearer
// the light than the point by more than a bias, its own object's left out as a shadow ray
// leaving it leaves them out. Texels are traced in tiles, each the first time a
// lookup needs it: a third to a half of a map's tiles are never looked up (the far side of the
// fur, the empty corners of its bounding sphere).
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "math/bounds.h"
#include "render/core/traced_scene.h"

namespace lat {

class DeepShadowMap {
public:
    // The map of the instances in `target` (world bounds) seen from `light`, `size` texels on a
    // side aimed at the sphere around target, traced through rs (which must outlive it). None
    // (valid() false) when the light lies within that sphere: a perspective map cannot hold it.
    // `where` names the light in messages (e.g. "lights[1]").
    DeepShadowMap(const TracedScene& rs, Vec3 light, const Bounds3& target, int size,
                  std::string where);
    DeepShadowMap(DeepShadowMap&&) noexcept;
    ~DeepShadowMap();

    bool valid() const { return valid_; }
    int size() const { return size_; }
    // The share of the light reaching p on a surface of object `self` (as rs numbers it)
    // through the instances, their crossings less than `bias` nearer the light than p, and
    // self's, not counted; 1 outside the map. Thread-safe: it traces the tiles
    // it needs that are not yet traced. Throws InputError naming the light once the map's
    // knots would pass kMaxMapBytes.
    double transmittance(Vec3 p, double bias,
                         std::uint32_t self = EmbreeAccel::kNoObject) const;
    // A texel's width at distance `dist` from the light, in world units.
    double texel_width(double dist) const { return dist * texel_angle_; }

    std::uint64_t tiles() const;
    std::uint64_t tiles_traced() const { return traced_->tiles.load(); }
    std::uint64_t knots() const { return traced_->knots.load(); }
    std::uint64_t bytes() const;

    static constexpr int kTile = 16;  // texels a side of a tile
    static constexpr std::uint64_t kMaxMapBytes = std::uint64_t{2} << 30;

private:
    // A crossing of a texel's ray: at `depth` from the light, object `object` covers `covered`
    // of the light left there.
    struct Knot {
        float depth;
        float covered;
        std::uint32_t object;
    };
    struct Tile;
    struct Traced {
        std::atomic<std::uint64_t> tiles{0}, knots{0};
    };

    const TracedScene* rs_ = nullptr;
    std::string where_;
    Vec3 eye_, u_, v_, w_;
    double focal_ = 1, texel_angle_ = 0;
    int size_ = 0, tiles_across_ = 0;
    bool valid_ = false;
    std::unique_ptr<Tile[]> tiles_;
    std::unique_ptr<Traced> traced_;

    const Tile& tile(int ti, int tj) const;
    void trace_tile(int ti, int tj, Tile& t) const;
    void trace_texel(int i, int j, std::vector<Knot>& out) const;
    double texel_left(int i, int j, double depth, std::uint32_t self) const;
};

}  // namespace lat
