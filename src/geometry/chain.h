#pragma once
// The paper's small primitive: spheres joined by flat-ended cylinders ("hair", "hook",
// "thistle spike"), the solid being the union of all of them.
#include <array>
#include <span>
#include <vector>

#include "geometry/capped_cylinder.h"
#include "geometry/lattice_source.h"
#include "geometry/parts.h"
#include "geometry/sphere.h"

namespace lat {

struct ChainSphere {
    Vec3 center;
    double radius;
};
struct ChainCylinder {
    int from, to;  // sphere indices
    double radius;
};

// Parts are numbered spheres first, then cylinders. Crossing::part = part << 2 | sub, where
// sub is the cylinder's surface (0 side, 1 and 2 the ends) and 0 for spheres.
class ChainShape final : public Shape, public Parts, public LatticeSource {
public:
    ChainShape(std::vector<ChainSphere> spheres, std::vector<ChainCylinder> cylinders);

    const std::vector<ChainSphere>& spheres() const { return spheres_; }
    const std::vector<ChainCylinder>& cylinders() const { return cylinders_; }
    // Its parts' indices, 0 to part_count() - 1, in the order intersect() tests them.
    std::span<const std::uint32_t> all_parts() const { return all_parts_; }

    Bounds3 bounds() const override { return bounds_; }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    // Inline and through the parts' concrete types: the rasterizer's call for every hit.
    Vec3 normal(const Ray& r, const Crossing& c) const override {
        const std::size_t i = c.part >> 2, spheres = sphere_parts_.size();
        const Crossing own{c.t, c.part & 3u, 0};
        return i < spheres ? sphere_parts_[i].normal(r, own) : cyl_parts_[i - spheres].normal(r, own);
    }
    // A part's index in the high bits, its own part number in the low two.
    bool names_surface(const Crossing& c) const override {
        const std::size_t i = c.part >> 2, spheres = sphere_parts_.size();
        if (i >= part_count()) return false;
        return i < spheres ? (c.part & 3u) == 0
                           : cyl_parts_[i - spheres].names_surface({c.t, c.part & 3u, 0});
    }
    bool inside(Vec3 p) const override;
    // Its parts, tested one by one.
    double intersect_cost() const override { return static_cast<double>(part_count()); }

    std::size_t part_count() const override { return sphere_parts_.size() + cyl_parts_.size(); }
    Bounds3 part_bounds(std::size_t i) const override;
    Bounds3 part_bounds(std::size_t i, const Transform& xf) const override {
        return part(i).placed_bounds(xf);
    }
    // Inline and through the parts' concrete types: the rasterizer's innermost call.
    bool intersect_part(std::size_t i, const Ray& r, double tmin, double tmax,
                             Crossing& hit) const override {
        const bool found = i < sphere_parts_.size()
                               ? sphere_parts_[i].intersect(r, tmin, tmax, hit)
                               : cyl_parts_[i - sphere_parts_.size()].intersect(r, tmin, tmax, hit);
        if (found) hit.part = static_cast<std::uint32_t>(i << 2) | hit.part;
        return found;
    }
    // Part i against two rays from one origin (geometry/ray_fan.h): the lanes (bits 0, 1) that
    // intersect_part finds a crossing for, with the part's own surface number in out.part.
    unsigned intersect_fan(std::size_t i, const RayFan& f, FanHits& out) const {
        return i < sphere_parts_.size() ? sphere_parts_[i].intersect_fan(f, out)
                                        : cyl_parts_[i - sphere_parts_.size()].intersect_fan(f, out);
    }
    void part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const override;
    void part_spans(std::size_t i, const Ray& r, SpanList& out) const override;
    // Spheres are capsules; so is the flat-ended cylinder's rim, within r of its axis segment.
    bool part_capsule(std::size_t i, Capsule& out) const override;
    bool occluded_part(std::size_t i, const Ray& r, double tmin, double tmax) const override {
        return part(i).occluded(r, tmin, tmax);
    }

    // Four parallel rays at once (geometry/ray_quad.h), each lane as the scalar loops answer
    // it, bit for bit: the lanes in `live` that first_crossing_of_parts over `parts` finds a
    // crossing for (kept in hits, the lanes' tmax narrowed to them), and the lanes in `live`
    // that any_part_occludes finds blocked.
    unsigned first_crossings(std::span<const std::uint32_t> parts, RayQuad& q, unsigned live,
                             QuadCrossings& hits) const;
    unsigned blocked_lanes(std::span<const std::uint32_t> parts, const RayQuad& q,
                           unsigned live) const;

private:
    std::vector<ChainSphere> spheres_;
    std::vector<ChainCylinder> cylinders_;
    std::vector<SphereShape> sphere_parts_;
    std::vector<CappedCylinderShape> cyl_parts_;
    Bounds3 bounds_;
    // 0 to part_count() - 1 (std::views::iota does not build with clang 14, the fuzzing
    // compiler, and g++ 12's library).
    std::vector<std::uint32_t> all_parts_;

    const Shape& part(std::size_t i) const;
};

// The chain s is, if it is one: the typed view that the rasterizer, coverage builds, sub-rays
// and the particle baseline take to trace the common primitive through its concrete parts,
// four or two rays at a time and without virtual calls in their innermost loops.
const ChainShape* as_chain(const Shape& s);

}  // namespace lat
