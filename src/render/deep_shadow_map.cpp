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
// stop (kMinTransmittance). Crossings that cover less than kMinDrop of what is left are gathered
// into one knot of their own once together they cover that much (what is left over at the end,
// under half an 8-bit step of the light, does not show).
constexpr double kMinDrop = 1.0 / 512;
// Crossings one map ray collects at most (the traversal's limit, as a camera ray's max_layers).
constexpr int kMaxCrossings = 256;
// Knots a texel keeps at most: past them, crossings are folded into the last.
constexpr std::size_t kMaxKnots = 64;

// Texel k of a tile's knots are [first[k], first[k + 1]): at most kMaxKnots a texel, so 16
// bits hold them.
using KnotIndex = std::uint16_t;

}  // namespace

MapFrame MapFrame::aimed(Vec3 light, const Bounds3& target) {
    MapFrame f;
    if (target.empty() || !target.finite()) return f;
    const Vec3 centre = target.center();
    const double radius = length(target.extent()) * 0.5;
    f.dist = length(centre - light);
    if (!(f.dist > radius * 1.001)) return f;
    f.tan_half = radius / std::sqrt(f.dist * f.dist - radius * radius);
    f.near = f.dist - radius;
    if (!std::isfinite(f.tan_half) || !std::isfinite(f.dist) || !(f.tan_half > 0)) return f;
    f.eye = light;
    f.w = (centre - light) / f.dist;
    const Vec3 up = std::abs(f.w.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0};
    f.u = normalize(cross(f.w, up));
    f.v = cross(f.u, f.w);
    f.valid = true;
    return f;
}

struct DeepShadowMap::Tile {
    std::once_flag once;
    std::vector<Knot> knots;
    std::vector<KnotIndex> first;  // allocated when the tile is traced, as the knots are
};
static_assert(DeepShadowMap::kTile * DeepShadowMap::kTile * kMaxKnots < 65536);

DeepShadowMap::DeepShadowMap(const TracedScene& rs, Vec3 light, const Bounds3& target, int size,
                             std::string where, MapBudget& budget)
    : rs_(&rs), where_(std::move(where)), frame_(MapFrame::aimed(light, target)), size_(size),
      budget_(&budget), traced_(std::make_unique<Traced>()) {
    assert(size > 0);
    if (!frame_.valid) return;
    focal_ = size / (2 * frame_.tan_half);
    texel_angle_ = 1 / focal_;
    tiles_across_ = (size + kTile - 1) / kTile;
    if (!budget.charge(tiles() * sizeof(Tile))) over_budget();
    tiles_ = std::make_unique<Tile[]>(tiles());
}

DeepShadowMap::DeepShadowMap(DeepShadowMap&&) noexcept = default;
DeepShadowMap::~DeepShadowMap() = default;

void DeepShadowMap::over_budget() const {
    budget_->over = true;
    throw InputError(located_message(
        rs_->scene().file, where_,
        "its deep shadow map would pass the " + std::to_string(budget_->limit >> 20) +
            " MB the maps may take, at " + std::to_string(size_) +
            " texels a side; give a smaller --shadow-map-size"));
}

std::uint64_t DeepShadowMap::tiles() const {
    return static_cast<std::uint64_t>(tiles_across_) * static_cast<std::uint64_t>(tiles_across_);
}

std::uint64_t DeepShadowMap::bytes() const {
    return tiles() * sizeof(Tile) + tiles_traced() * (kTile * kTile + 1) * sizeof(KnotIndex) +
           knots() * sizeof(Knot);
}

const DeepShadowMap::Tile& DeepShadowMap::tile(int ti, int tj) const {
    Tile& t = tiles_[static_cast<std::size_t>(tj) * static_cast<std::size_t>(tiles_across_) +
                     static_cast<std::size_t>(ti)];
    // The budget is checked outside call_once: a tile traced past it is kept, and the throw
    // ends the render.
    std::call_once(t.once, [&] { trace_tile(ti, tj, t); });
    if (budget_->over) over_budget();
    return t;
}

void DeepShadowMap::trace_tile(int ti, int tj, Tile& t) const {
    std::vector<Knot> texel;
    t.first.assign(kTile * kTile + 1, 0);
    for (int y = 0; y < kTile; ++y)
        for (int x = 0; x < kTile; ++x) {
            const int i = ti * kTile + x, j = tj * kTile + y;
            if (i < size_ && j < size_) trace_texel(i, j, texel);
            else texel.clear();
            t.knots.insert(t.knots.end(), texel.begin(), texel.end());
            t.first[static_cast<std::size_t>(y * kTile + x + 1)] =
                static_cast<KnotIndex>(t.knots.size());
        }
    t.knots.shrink_to_fit();
    traced_->tiles.fetch_add(1, std::memory_order_relaxed);
    traced_->knots.fetch_add(t.knots.size(), std::memory_order_relaxed);
    if (!budget_->charge(t.first.size() * sizeof(KnotIndex) + t.knots.size() * sizeof(Knot)))
        budget_->over = true;
}

// Texel (i, j)'s ray from the light, with the texel's footprint, through the instances: a knot
// at each crossing that covers kMinDrop or more of what is left of it, fainter ones gathered.
void DeepShadowMap::trace_texel(int i, int j, std::vector<Knot>& out) const {
    out.clear();
    const double x = (i + 0.5 - size_ / 2.0) / focal_, y = (size_ / 2.0 - (j + 0.5)) / focal_;
    const Vec3 d = normalize(frame_.w + frame_.u * x + frame_.v * y);
    const TraceRay ray{frame_.eye, d, footprint_across(d, 0, texel_angle_, true)};
    thread_local std::vector<AccelHit> partial;
    AccelHit opaque;
    const LayerStop stop{.max_layers = kMaxCrossings, .min_left = kMinTransmittance};
    const bool found = rs_->crossings(ray.ray(), 0, kInfinity, partial, opaque, stop);
    // A knot of share c at t; folded into the last once a texel is full (its object then none,
    // so that no point leaves it out as its own).
    const auto keep = [&](double t, double c, std::uint32_t object) {
        const auto depth = static_cast<float>(t - frame_.near);
        if (out.size() < kMaxKnots) {
            out.push_back({depth, static_cast<float>(c), object});
            return;
        }
        Knot& last = out.back();
        last.covered = static_cast<float>(1 - (1 - double(last.covered)) * (1 - c));
        last.object = EmbreeAccel::kNoObject;
    };
    LayerComposite seen;
    double pending = 0;  // what faint crossings not yet kept cover, together (no object's own)
    for (const AccelHit& h : partial) {
        const double c = seen.add(h.crossing);
        if (c >= kMinDrop) {
            keep(h.t, c, h.object);
            continue;
        }
        pending = 1 - (1 - pending) * (1 - c);
        if (pending >= kMinDrop) {
            keep(h.t, pending, EmbreeAccel::kNoObject);
            pending = 0;
        }
    }
    // An opaque instance blocks the rest; an opaque object that is not an instance is the
    // shadow rays' to find (the map keeps what lies in front of it).
    if (found && seen.left() > kMinTransmittance && rs_->scene().primitive_of(opaque.object) >= 0)
        keep(opaque.t, 1, opaque.object);
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
    if (!frame_.valid) return 1;
    const Vec3 d = p - frame_.eye;
    const double z = dot(d, frame_.w);
    if (!(z > 0)) return 1;
    // Texel coordinates, texel centres at half-integers; bilinear between the four around p.
    const double x = size_ / 2.0 + focal_ * dot(d, frame_.u) / z - 0.5;
    const double y = size_ / 2.0 - focal_ * dot(d, frame_.v) / z - 0.5;
    if (!(x > -1 && y > -1 && x < size_ && y < size_)) return 1;
    const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
    const double fx = x - i, fy = y - j, depth = length(d) - bias - frame_.near;
    const auto at = [&](int a, int b) { return texel_left(a, b, depth, self); };
    return (1 - fy) * ((1 - fx) * at(i, j) + fx * at(i + 1, j)) +
           fy * ((1 - fx) * at(i, j + 1) + fx * at(i + 1, j + 1));
}

}  // namespace lat
