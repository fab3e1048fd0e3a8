#pragma once
// A triangle mesh as a shape: traced exactly in double precision (Moller-Trumbore), shaded with
// the file's vertex normals where a triangle has them at all three corners and with its face
// normal elsewhere, so that creases stay sharp unless the file (or `smooth`: area-weighted
// averages of the faces around each vertex) says otherwise. Each triangle is one part
// (geometry/parts.h), so the accelerator holds them one by one. A closed mesh (every edge shared
// by exactly two triangles, consistently oriented) is also a solid for CSG, inside by ray
// parity; an open one is only a surface.
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include "geometry/lattice_source.h"
#include "geometry/mesh_bvh.h"
#include "geometry/parts.h"
#include "geometry/shape.h"

namespace lat {

// Moller-Trumbore: the ray parameter t and barycentrics (u, v) of the crossing with triangle
// (a, b, c), the point being (1-u-v) a + u b + v c. Edges count (with a tolerance of 1e-12 in
// barycentrics), so that a ray through a shared edge is never lost between two triangles.
bool intersect_triangle(const Ray& r, Vec3 a, Vec3 b, Vec3 c, double& t, double& u, double& v);

class TriangleMeshShape final : public Shape, public Parts, public LatticeSource {
public:
    using Triangle = std::array<std::uint32_t, 3>;
    // Inputs must be valid (finite, indices in range: io/mesh_file.h checks files). `normals`:
    // per vertex, zero where there is none, or empty for none at all. `smooth`: vertices without
    // a normal get the area-weighted average of the faces that share them (by index).
    TriangleMeshShape(std::vector<Vec3> positions, std::vector<Triangle> triangles,
                      std::vector<Vec3> normals = {}, bool smooth = false);

    bool closed() const { return closed_; }
    const std::vector<Vec3>& positions() const { return positions_; }
    const std::vector<Triangle>& triangles() const { return triangles_; }
    // The unit face normal (outward for a closed mesh) and the shading normal at (u, v): the
    // blend of the three vertex normals, or the face normal where a corner has none.
    Vec3 face_normal(std::size_t tri) const;
    Vec3 shading_normal(std::size_t tri, double u, double v) const;

    Bounds3 bounds() const override { return bounds_; }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override;
    bool occluded(const Ray& r, double tmin, double tmax) const override;
    void spans(const Ray& r, SpanList& out) const override;
    Vec3 normal(const Ray& r, const Crossing& c) const override;
    bool inside(Vec3 p) const override;
    bool names_surface(const Crossing& c) const override { return c.part < triangles_.size(); }

    // intersect() descends its own hierarchy: about two boxes a level and a leaf's triangles.
    double intersect_cost() const override {
        return 2.0 * std::bit_width(triangles_.size()) + 4;
    }
    std::size_t part_count() const override { return triangles_.size(); }
    Bounds3 part_bounds(std::size_t i) const override;
    Bounds3 part_bounds(std::size_t i, const Transform& xf) const override;
    bool intersect_part(std::size_t i, const Ray& r, double tmin, double tmax,
                             Crossing& hit) const override;
    bool occluded_part(std::size_t i, const Ray& r, double tmin, double tmax) const override;
    // The whole mesh's spans: a triangle bounds no solid on its own.
    void part_spans(std::size_t i, const Ray& r, SpanList& out) const override;
    // The sphere around the triangle's box.
    void part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const override;

private:
    std::vector<Vec3> positions_;
    std::vector<Triangle> triangles_;
    std::vector<Vec3> normals_;  // unit or zero (none), per vertex; empty: all none
    Bounds3 bounds_;
    MeshBvh bvh_;
    bool closed_ = false;
    bool flip_ = false;  // closed and wound inwards: face normals are turned to point out

    void compute_normals(bool smooth);
    void check_closed();
};

// The mesh s is, if it is one: the typed view for what needs its triangles or whether it is
// closed (the texture baseline's atlas).
const TriangleMeshShape* as_mesh(const Shape& s);

}  // namespace lat
