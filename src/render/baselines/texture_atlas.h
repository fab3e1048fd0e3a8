#pragma once
// Where the texture mode's texels lie on a base surface (render/baselines/texture_mode.h): a layout of
// texels over the surface, the surface points inside each texel (for baking) and the texels
// around a surface point with their bilinear weights (for lookups). Everything is in the base
// object's own coordinates.
//
// - Spheres and ellipsoids: one equirectangular map, width x width/2 texels, wrapping in
//   longitude; row 0 at the +z pole.
// - Triangle meshes, which carry no UV parametrisation: a texel grid per triangle, as Ptex
//   (Burley and Lacewell 2008) gives every face its own texture. Triangle (a, b, c) at
//   barycentrics (u, v) is the point (u, v) of a grid of n x n square cells over its
//   parameter square, of which the n (n + 1) / 2 cells touching the triangle (i + j < n) are
//   stored; n is chosen per triangle from its world area so that all texels have about the
//   same world area, the whole mesh getting about as many texels as the sphere map would.
//   Lookups filter bilinearly within a triangle's grid (texels off the triangle are left
//   out and the weights renormalised), not across its edges (Ptex filters across them with
//   its adjacency data; the seams this leaves are below a texel in size).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "geometry/shape.h"
#include "scene/scene.h"

namespace lat {

struct TexelWeights {
    std::array<std::size_t, 4> texel{};
    std::array<double, 4> weight{};
    int count = 0;
};

class TextureAtlas {
public:
    virtual ~TextureAtlas() = default;
    virtual std::size_t texel_count() const = 0;
    // Bytes of the layout itself, beside the texels (a mesh's per-triangle grid sizes).
    virtual std::uint64_t layout_bytes() const = 0;
    // The surface point and unit outward normal at (a, b) in [0, 1)^2 across texel t; false
    // when that point is off the surface (the outer half of a triangle's diagonal texels).
    virtual bool texel_point(std::size_t t, double a, double b, SurfacePoint& out) const = 0;
    // The surface area texel t covers (object units).
    virtual double texel_area(std::size_t t) const = 0;
    // The texels around point p of the surface, on part `part` of the shape (a mesh's
    // triangle), weights summing to 1.
    virtual TexelWeights lookup(Vec3 p, std::uint32_t part) const = 0;
};

// Whether the texture mode has a layout for this object's shape.
bool has_texture_atlas(const SceneObject& base);

// An atlas over base's surface of width x width / 2 texels (about as many, for a mesh).
// Asserts has_texture_atlas(base).
std::unique_ptr<TextureAtlas> make_texture_atlas(const SceneObject& base, int width);

// The equirectangular parameters (u across, v down from +z, both 0..1) of a unit direction.
void direction_to_uv(Vec3 d, double& u, double& v);
Vec3 uv_to_direction(double u, double v);

}  // namespace lat
