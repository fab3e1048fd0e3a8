#include "geometry/chain.h"

#include <algorithm>
#include <cmath>

#include "geometry/ray_quad.h"

namespace lat {

ChainShape::ChainShape(std::vector<ChainSphere> spheres, std::vector<ChainCylinder> cylinders)
    : spheres_(std::move(spheres)), cylinders_(std::move(cylinders)) {
    for (const ChainSphere& s : spheres_) sphere_parts_.emplace_back(s.center, s.radius);
    for (const ChainCylinder& c : cylinders_)
        cyl_parts_.emplace_back(spheres_[static_cast<std::size_t>(c.from)].center,
                                spheres_[static_cast<std::size_t>(c.to)].center, c.radius);
    for (std::size_t i = 0; i < part_count(); ++i) {
        bounds_ = merge(bounds_, part(i).bounds());
        all_parts_.push_back(static_cast<std::uint32_t>(i));
    }
}

const Shape& ChainShape::part(std::size_t i) const {
    if (i < sphere_parts_.size()) return sphere_parts_[i];
    return cyl_parts_[i - sphere_parts_.size()];
}

Bounds3 ChainShape::part_bounds(std::size_t i) const { return part(i).bounds(); }

void ChainShape::part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
    if (i < sphere_parts_.size()) {
        out.push_back({sphere_parts_[i].center(), sphere_parts_[i].radius()});
        return;
    }
    // A cylinder of length L and radius r as n slices of length L/n, each inside a sphere of
    // radius sqrt(r^2 + (L/2n)^2); slices about as long as the diameter keep that near r.
    const ChainCylinder& c = cylinders_[i - sphere_parts_.size()];
    const Vec3 a = spheres_[static_cast<std::size_t>(c.from)].center;
    const Vec3 b = spheres_[static_cast<std::size_t>(c.to)].center;
    const double len = length(b - a);
    const int n = std::max(1, static_cast<int>(std::ceil(len / (1.5 * c.radius))));
    const double half = 0.5 * len / n;
    const double rad = std::sqrt(c.radius * c.radius + half * half);
    for (int k = 0; k < n; ++k) out.push_back({lerp(a, b, (k + 0.5) / n), rad});
}

bool ChainShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    // From outside, the union's first crossing is the first crossing of any part.
    return first_crossing_of_parts(*this, all_parts_, r, tmin, tmax, hit);
}

bool ChainShape::occluded(const Ray& r, double tmin, double tmax) const {
    for (std::size_t i = 0; i < part_count(); ++i)
        if (part(i).occluded(r, tmin, tmax)) return true;
    return false;
}

unsigned ChainShape::first_crossings(std::span<const std::uint32_t> parts, RayQuad& q,
                                     unsigned live, QuadCrossings& hits) const {
    unsigned found = 0;
    for (const std::uint32_t i : parts) {
        const unsigned m = i < sphere_parts_.size()
                               ? sphere_parts_[i].intersect_quad(q, live, hits)
                               : cyl_parts_[i - sphere_parts_.size()].intersect_quad(q, live, hits);
        for (int k = 0; k < 4; ++k)
            if (m >> k & 1) hits.c[k].part = i << 2 | hits.c[k].part;
        found |= m;
    }
    return found;
}

unsigned ChainShape::blocked_lanes(std::span<const std::uint32_t> parts, const RayQuad& q,
                                   unsigned live) const {
    unsigned blocked = 0;
    for (const std::uint32_t i : parts) {
        const unsigned open = live & ~blocked;
        if (open == 0) break;
        blocked |= i < sphere_parts_.size() ? sphere_parts_[i].occluded_quad(q, open)
                                            : cyl_parts_[i - sphere_parts_.size()].occluded_quad(q, open);
    }
    return blocked;
}

void ChainShape::part_spans(std::size_t i, const Ray& r, SpanList& out) const {
    const std::size_t before = out.size();
    part(i).spans(r, out);
    for (std::size_t k = before; k < out.size(); ++k) {
        out[k].in.part = static_cast<std::uint32_t>(i << 2) | out[k].in.part;
        out[k].out.part = static_cast<std::uint32_t>(i << 2) | out[k].out.part;
    }
}

void ChainShape::spans(const Ray& r, SpanList& out) const {
    const std::size_t first = out.size();
    for (std::size_t i = 0; i < part_count(); ++i) part_spans(i, r, out);
    merge_span_union(out, first);
}

bool ChainShape::part_capsule(std::size_t i, Capsule& out) const {
    if (i < spheres_.size()) {
        out = {spheres_[i].center, spheres_[i].center, spheres_[i].radius};
    } else {
        const ChainCylinder& c = cylinders_[i - spheres_.size()];
        out = {spheres_[static_cast<std::size_t>(c.from)].center,
               spheres_[static_cast<std::size_t>(c.to)].center, c.radius};
    }
    return true;
}

bool ChainShape::inside(Vec3 p) const {
    for (std::size_t i = 0; i < part_count(); ++i)
        if (part(i).inside(p)) return true;
    return false;
}

const ChainShape* as_chain(const Shape& s) { return dynamic_cast<const ChainShape*>(&s); }

}  // namespace lat
