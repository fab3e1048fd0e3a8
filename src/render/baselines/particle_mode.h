#pragma once
// --mode particles: the paper's "particle system" column (Table 2), rendered as Reeves (1983)
// and the fur renderers after him would: every instance becomes a stream of particles along
// its parts, drawn without ray tracing as depth-tested, antialiased splats in screen space.
//
// - Particles: each cylinder of an instance's chain primitive is cut into segments no longer
//   than twice its radius (a sphere no cylinder joins is a point particle); each keeps the
//   part's radius (scaled by the instance's mean scale) and the instance's material.
// - Hiding: the image is supersampled on the --spp grid (nx x ny regular sub-pixel positions,
//   as a z-buffer renderer supersamples); a particle covers a sample within its projected
//   radius of its projected axis, at the depth of the hair's near side there; the nearest
//   sample wins (ties: the earlier particle) and samples are box-filtered into the pixel.
// - Shading: Kajiya-Kay from the particle's tangent, flat per particle, for every light.
// - The base (every non-instance object) is ray traced at the same samples and shaded by the
//   reference Phong rule; its depth is the z-buffer the particles are composited into, as a
//   particle renderer composites over a rendered background plate.
// - Shadows (when the scene has them): a shadow map of the particles per light (perspective,
//   aimed at the particles' bounding sphere, percentage-closer filtered 3 x 3, biased by twice
//   the thickest particle's radius), which both the particles and the base look up; the
//   base's own shadows, on itself and on the particles, are shadow rays against the base.
#include <cstdint>
#include <vector>

#include "render/core/renderer.h"
#include "scene/scene.h"

namespace lat {

struct Particle {
    Vec3 a, b;             // the segment, world space (a == b for a point particle)
    double radius = 0;     // world units
    std::uint32_t material = 0;
};

struct ParticleSet {
    std::vector<Particle> particles;
    std::uint64_t bytes() const { return particles.size() * sizeof(Particle); }
};

// Throws InputError naming the object when an instance's primitive is not a sphere/cylinder
// chain (a particle system needs strands).
ParticleSet make_particles(const Scene& scene);

struct ParticleOptions {
    int spp = 1;                 // the sub-sample grid per pixel (see stratify)
    int shadow_map_size = 2048;  // texels on a side, per light
    bool progress = false;
};

// The image; stats.render_ms includes the shadow maps.
RenderOutput render_particles(const Scene& scene, const ParticleSet& set, const ParticleOptions& opt);

}  // namespace lat
