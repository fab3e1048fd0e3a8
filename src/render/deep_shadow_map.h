#pragma once
// Deep shadow maps (Lokovic and Veach, "Deep Shadow Maps", SIGGRAPH 2000) of the instances
// answered through their footprints, one per point light: shadow rays among fur spend most of a
// layered render (each starts inside tens of other hairs' boxes and visits them all), where a
// map answers each in one lookup. The map is traced from the light through the same filtered
// tables a shadow ray reads: one ray per texel, its footprint the texel's, keeping each crossing
// it meets (a knot: its distance from the light, the share of the light it covers, its object).
// A point reads the light that reaches it from the four texels around it: the crossings nearer
// the light than the point by more than a bias, its own object's left out as a shadow ray
// leaving it leaves them out. Texels are traced in tiles, each the first time a lookup needs
// it: the far side of the fur and the empty corners of its bounding sphere are never traced.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "math/bounds.h"
#include "render/core/traced_scene.h"

namespace lat {

// A perspective view from a light aimed at the sphere around `target` (world bounds), which it
// holds whole. None (valid false) when the light lies within the sphere, or the figures are not
// finite.
struct MapFrame {
    Vec3 eye, u, v, w;
    double tan_half = 0;  // of the cone around the sphere
    double dist = 0;      // from the light to the sphere's centre
    double near = 0;      // from the light to the sphere's near side
    bool valid = false;

    static MapFrame aimed(Vec3 light, const Bounds3& target);
    // The cone's width at the sphere's centre (world units).
    double width_at_centre() const { return 2 * tan_half * dist; }
};

// The bytes all of a render's maps may take, shared by them; past it a lookup that would trace
// more throws InputError naming its light.
struct MapBudget {
    explicit MapBudget(std::uint64_t limit_) : limit(limit_) {}
    std::uint64_t limit;
    std::atomic<std::uint64_t> used{0};
    std::atomic<bool> over{false};
    // Adds n bytes; whether they are within the limit.
    bool charge(std::uint64_t n) { return (used += n) <= limit; }
};

class DeepShadowMap {
public:
    // The map of the instances in `target` seen from `light` (MapFrame::aimed), `size` texels on
    // a side, traced through rs (which must outlive it), its bytes charged to `budget` (which
    // must outlive it too). `where` names the light in messages (e.g. "lights[1]"). Throws
    // InputError when its tiles' index alone passes the budget.
    DeepShadowMap(const TracedScene& rs, Vec3 light, const Bounds3& target, int size,
                  std::string where, MapBudget& budget);
    DeepShadowMap(DeepShadowMap&&) noexcept;
    ~DeepShadowMap();

    bool valid() const { return frame_.valid; }
    int size() const { return size_; }
    // The share of the light reaching p on a surface of object `self` (as rs numbers it)
    // through the instances, their crossings less than `bias` nearer the light than p, and
    // self's, not counted; 1 outside the map. Thread-safe: it traces the tiles it needs that are
    // not yet traced. Throws InputError naming the light once the maps pass their budget.
    double transmittance(Vec3 p, double bias,
                         std::uint32_t self = EmbreeAccel::kNoObject) const;
    // A texel's width at distance `dist` from the light, in world units.
    double texel_width(double dist) const { return dist * texel_angle_; }

    std::uint64_t tiles() const;
    std::uint64_t tiles_traced() const { return traced_->tiles.load(); }
    std::uint64_t knots() const { return traced_->knots.load(); }
    std::uint64_t bytes() const;

    static constexpr int kTile = 16;  // texels a side of a tile

private:
    // A crossing of a texel's ray: at `depth` from the sphere's near side, object `object` (or
    // none: several crossings folded together) covers `covered` of the light left there.
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
    MapFrame frame_;
    double focal_ = 1, texel_angle_ = 0;
    int size_ = 0, tiles_across_ = 0;
    MapBudget* budget_ = nullptr;
    std::unique_ptr<Tile[]> tiles_;
    std::unique_ptr<Traced> traced_;

    const Tile& tile(int ti, int tj) const;
    void trace_tile(int ti, int tj, Tile& t) const;
    void trace_texel(int i, int j, std::vector<Knot>& out) const;
    double texel_left(int i, int j, double depth, std::uint32_t self) const;
    [[noreturn]] void over_budget() const;
};

}  // namespace lat
