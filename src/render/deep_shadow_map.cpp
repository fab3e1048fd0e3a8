#include "render/deep_shadow_map.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "coverage/layers.h"
#include "render/core/camera.h"
#include "util/error.h"

namespace lat {
namespace {

// A map ray's crossings are kept until what it lets through falls below the shadow rays' own
// stop (kMinTransmittance); one that covers less than kMinDrop of what is left is not kept
// (less than an 8-bit step of the light: it does not show).
constexpr double kMinDrop = 1.0 / 512;
// Crossings one map ray collects at most (the traversal's limit, as a camera ray's max_layers).
constexpr int kMaxCrossings = 256;
// Knots a texel keeps at most: past them, the rest of its ray is not kept.
constexpr std::size_t kMaxKnots = 64;

}  // namespace

struct DeepShadowMap::Tile {
    std::once_flag once;
    std::vector<Knot> knots;
    // Texel k of the tile (row by row) holds knots [first[k], first[k + 1]): at most kMaxKnots
    // a texel, so 16 bits hold them. Allocated when the tile is traced, as the knots are.
    std::vector<std::uint16_t> first;
};
static_assert(DeepShadowMap::kTile * DeepShadowMap::kTile * kMaxKnots < 65536);

DeepShadowMap::DeepShadowMap(const TracedScene& rs, Vec3 light, const Bounds3& target, int size,
                             std::string where)
    : rs_(&rs), where_(std::move(where)), size_(size), traced_(std::make_unique<Traced>()) {
    assert(size > 0);
    if (target.empty() || !target.finite()) return;
    const Vec3 centre = target.center();
    const double radius = length(target.extent()) * 0.5, dist = length(centre - light);
    if (dist <= radius * 1.001) return;
    eye_ = light;
    w_ = (centre - light) / dist;
    const Vec3 up = std::abs(w_.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0};
    u_ = normalize(cross(w_, up));
    v_ = cross(u_, w_);
    const double tan_half = radius / std::sqrt(dist * dist - radius * radius);
    focal_ = size / (2 * tan_half);
    texel_angle_ = 1 / focal_;
    tiles_across_ = (size + kTile - 1) / kTile;
    tiles_ = std::make_unique<Tile[]>(tiles());
    valid_ = true;
}

DeepShadowMap::DeepShadowMap(DeepShadowMap&&) noexcept = default;
DeepShadowMap::~DeepShadowMap() = default;

std::uint64_t DeepShadowMap::tiles() const {
    return static_cast<std::uint64_t>(tiles_across_) * static_cast<std::uint64_t>(tiles_across_);
}

std::uint64_t DeepShadowMap::bytes() const {
    return tiles() * sizeof(Tile) +
           tiles_traced() * (kTile * kTile + 1) * sizeof(std::uint16_t) + knots() * sizeof(Knot);
}

const DeepShadowMap::Tile& DeepShadowMap::tile(int ti, int tj) const {
    Tile& t = tiles_[static_cast<std::size_t>(tj) * static_cast<std::size_t>(tiles_across_) +
                     static_cast<std::size_t>(ti)];
    std::call_once(t.once, [&] { trace_tile(ti, tj, t); });
    return t;
}

void DeepShadowMap::trace_tile(int ti, int tj, Tile& t) const {
    std::vector<Knot> texel;
    t.knots.clear();  // a try that threw (InputError) may have left some
    t.first.assign(kTile * kTile + 1, 0);
    for (int y = 0; y < kTile; ++y)
        for (int x = 0; x < kTile; ++x) {
            const int i = ti * kTile + x, j = tj * kTile + y;
            if (i < size_ && j < size_) trace_texel(i, j, texel);
            else texel.clear();
            t.knots.insert(t.knots.end(), texel.begin(), texel.end());
            t.first[static_cast<std::size_t>(y * kTile + x + 1)] =
                static_cast<std::uint16_t>(t.knots.size());
        }
    t.knots.shrink_to_fit();
    traced_->tiles.fetch_add(1, std::memory_order_relaxed);
    const std::uint64_t total =
        traced_->knots.fetch_add(t.knots.size(), std::memory_order_relaxed) + t.knots.size();
    if (total * sizeof(Knot) > kMaxMapBytes)
        throw InputError(located_message(rs_->scene().file, where_,
                                         "its deep shadow map would take more than " +
                                             std::to_string(kMaxMapBytes >> 20) + " MB at " +
                                             std::to_string(size_) +
                                             " texels a side; give a smaller --shadow-map-size"));
}

// Texel (i, j)'s ray from the light, with the texel's footprint, through the instances: a knot
// at each crossing that covers kMinDrop or more of what is left of it.
void DeepShadowMap::trace_texel(int i, int j, std::vector<Knot>& out) const {
    out.clear();
    const double x = (i + 0.5 - size_ / 2.0) / focal_, y = (size_ / 2.0 - (j + 0.5)) / focal_;
    const Vec3 d = normalize(w_ + u_ * x + v_ * y);
    const TraceRay ray{eye_, d, footprint_across(d, 0, texel_angle_, true)};
    thread_local std::vector<AccelHit> partial;
    AccelHit opaque;
    const LayerStop stop{.max_layers = kMaxCrossings, .min_left = kMinTransmittance};
    const bool found = rs_->crossings(ray.ray(), 0, kInfinity, partial, opaque, stop);
    LayerComposite seen;
    for (const AccelHit& h : partial) {
        const double covered = seen.add(h.crossing);
        if (covered >= kMinDrop && out.size() < kMaxKnots)
            out.push_back({static_cast<float>(h.t), static_cast<float>(covered), h.object});
        if (seen.left() <= kMinTransmittance) return;
    }
    // An opaque instance blocks the rest; an opaque object that is not an instance is the
    // shadow rays' to find (the map keeps what lies in front of it).
    if (found && rs_->scene().primitive_of(opaque.object) >= 0 && out.size() < kMaxKnots)
        out.push_back({static_cast<float>(opaque.t), 1.0f, opaque.object});
}

double DeepShadowMap::texel_left(int i, int j, double depth, std::uint32_t self) const {
    if (i < 0 || j < 0 || i >= size_ || j >= size_) return 1;
    const Tile& t = tile(i / kTile, j / kTile);
    const std::size_t k = static_cast<std::size_t>((j % kTile) * kTile + i % kTile);
    double left = 1;
    for (std::size_t n = t.first[k]; n < t.first[k + 1] && double(t.knots[n].depth) < depth; ++n)
        if (t.knots[n].object != self) left *= 1 - double(t.knots[n].covered);
    return left;
}

double DeepShadowMap::transmittance(Vec3 p, double bias, std::uint32_t self) const {
    if (!valid_) return 1;
    const Vec3 d = p - eye_;
    const double z = dot(d, w_);
    if (z <= 0) return 1;
    // Texel coordinates, texel centres at half-integers; bilinear between the four around p.
    const double x = size_ / 2.0 + focal_ * dot(d, u_) / z - 0.5;
    const double y = size_ / 2.0 - focal_ * dot(d, v_) / z - 0.5;
    if (!(x > -1 && y > -1 && x < size_ && y < size_)) return 1;
    const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
    const double fx = x - i, fy = y - j, depth = length(d) - bias;
    const auto at = [&](int a, int b) { return texel_left(a, b, depth, self); };
    return (1 - fy) * ((1 - fx) * at(i, j) + fx * at(i + 1, j)) +
           fy * ((1 - fx) * at(i, j + 1) + fx * at(i + 1, j + 1));
}


}  // namespace lat
