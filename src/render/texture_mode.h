#pragma once
// --mode texture: the paper's "texture mapping" column (Table 2), done as a texture artist
// would with the exact fur at hand: the instances are removed and replaced by maps on the
// surface they grow from, baked from their exact geometry and shaded at render time.
//
// - The base surface is inferred from where the instances are rooted: of the scene's spheres
//   and ellipsoids, the one whose surface lies nearest (mean distance) to the instances'
//   roots (the centre of the bottom of each primitive's lattice box, or of its bounds, placed
//   by the instance's transform: where `scatter` puts the surface point). Its map is
//   equirectangular over the (object-space) sphere, width x width/2 texels.
// - Baking: each texel is sampled on an s x s grid; at each sample a ray comes down the
//   surface normal from above the tallest instance and meets the exact instances (or not).
//   Coverage is the share of samples that hit fur; colour the mean of the hit materials'
//   colours; normal the normalised mean of the hit normals (object space). Stored 8 bits per
//   channel, as an RGBA colour+coverage map and an RGB normal map.
// - Shading: at the base, bilinear lookups; the pixel is the base material's Phong under the
//   geometric normal, blended by coverage with the fur material's Phong (the instances' most
//   common material, with the baked colour) under the baked normal. Shadows are those of the
//   textured surface: shadow rays against the scene without its instances.
#include <cstdint>
#include <vector>

#include "render/renderer.h"
#include "scene/scene.h"

namespace lat {

struct TextureMaps {
    std::size_t base_object = 0;    // in scene.objects
    std::uint32_t fur_material = 0;
    int width = 0, height = 0;
    std::vector<std::uint8_t> colour_coverage;  // RGBA per texel, row 0 at the +z pole
    std::vector<std::uint8_t> normal;           // RGB per texel: (n + 1) / 2, object space

    std::uint64_t bytes() const { return colour_coverage.size() + normal.size(); }
    // Bilinear lookups at object-space direction d from the base's centre.
    struct Sample {
        Vec3 colour;
        double coverage;
        Vec3 normal;  // object space, unit
    };
    Sample lookup(Vec3 d) const;
};

struct TextureOptions {
    int width = 1024;     // the map is width x width / 2
    int subsamples = 4;   // per side of a texel
    bool progress = false;
};

// The base surface (index in scene.objects) of the scene's instances, as described above;
// throws InputError when there are instances but no sphere or ellipsoid for them.
std::size_t texture_base(const Scene& scene);

// Throws as texture_base. A scene without instances gets empty maps.
TextureMaps bake_texture(const Scene& scene, const TextureOptions& opt);

// The equirectangular parameters (u across, v down from +z, both 0..1) of a unit direction.
void direction_to_uv(Vec3 d, double& u, double& v);
Vec3 uv_to_direction(double u, double v);

// The scene without its instances, the base surface shaded through the maps.
RenderOutput render_texture(const Scene& scene, const TextureMaps& maps, const RenderOptions& opt);

}  // namespace lat
