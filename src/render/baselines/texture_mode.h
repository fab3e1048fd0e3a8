#pragma once
// --mode texture: the paper's "texture mapping" column (Table 2), done as a texture artist
// would with the exact fur at hand: the instances are removed and replaced by maps on the
// surface they grow from, baked from their exact geometry and shaded at render time.
//
// - The base surface is inferred from where the instances are rooted (the centre of the bottom
//   of each primitive's lattice box, or of its bounds, placed by the instance's transform: where
//   `scatter` puts the surface point): of the scene's other objects, the one whose surface the
//   line through each root along the instance's up axis meets nearest to the root (median over
//   up to 1,024 instances spread over the list). Scatter roots lie on their surface, so a
//   scatter's "on" object is found at distance zero. Spheres, ellipsoids and triangle meshes
//   can be mapped (render/baselines/texture_atlas.h: an equirectangular map, or per-triangle texel grids
//   for meshes, which have no parametrisation); any other base is refused, and so is fur
//   standing apart from the base (one base a scene).
// - Baking: each texel is sampled on an s x s grid; at each sample a ray comes down the
//   surface normal from above the highest reach of the fur (an instance's size plus its root's
//   distance from the base), or from the base itself where it folds back over the sample
//   closer than that, and meets the exact instances (or not). Coverage is
//   the share of samples that hit fur; colour the mean of the hit materials' colours; normal
//   the normalised mean of the hit normals (object space). Stored 8 bits per channel, as an
//   RGBA colour+coverage map and an RGB normal map.
// - Shading: at the base, bilinear lookups; the pixel is the base material's Phong under the
//   geometric normal, blended by coverage with the fur material's Phong (the instances' most
//   common material, with the baked colour) under the baked normal. Shadows are those of the
//   textured surface: shadow rays against the scene without its instances.
#include <cstdint>
#include <memory>
#include <vector>

#include "render/core/renderer.h"
#include "render/baselines/texture_atlas.h"
#include "scene/scene.h"

namespace lat {

struct TextureMaps {
    std::size_t base_object = 0;    // in scene.objects
    std::uint32_t fur_material = 0;
    std::shared_ptr<const TextureAtlas> atlas;  // null when the scene has no instances
    std::vector<std::uint8_t> colour_coverage;  // RGBA per texel of the atlas
    std::vector<std::uint8_t> normal;           // RGB per texel: (n + 1) / 2, object space

    std::uint64_t bytes() const {
        return colour_coverage.size() + normal.size() + (atlas ? atlas->layout_bytes() : 0);
    }
    double coverage(std::size_t texel) const { return colour_coverage[4 * texel + 3] / 255.0; }
    // Bilinear lookups at point p on part `part` of the base (its coordinates); `geometric`
    // (unit, object space) stands in for the normal where no texel around has one.
    struct Sample {
        Vec3 colour;
        double coverage;
        Vec3 normal;  // object space, unit
    };
    Sample lookup(Vec3 p, std::uint32_t part, Vec3 geometric) const;
};

struct TextureOptions {
    int width = 1024;     // width x width / 2 texels (a sphere's map; as many over a mesh)
    int subsamples = 4;   // per side of a texel
    bool progress = false;
};

// The base surface (index in scene.objects) of the scene's instances, as described above;
// throws InputError when no object lies under the instances' roots, when the one that does
// cannot be mapped, or when an instance stands apart from it (farther than its own size).
std::size_t texture_base(const Scene& scene);

// Throws as texture_base. A scene without instances gets empty maps.
TextureMaps bake_texture(const Scene& scene, const TextureOptions& opt);

// The scene without its instances, the base surface shaded through the maps.
RenderOutput render_texture(const Scene& scene, const TextureMaps& maps, const RenderOptions& opt);

}  // namespace lat
