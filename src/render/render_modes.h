#pragma once
// The render modes, each one entry here: its name on the command line, what it is, and how a
// scene is rendered in it. `render` and `table2` both go through render_in_mode, so a mode is
// never dispatched by name twice.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "accel/embree_accel.h"
#include "lattice/cache/table_spec.h"
#include "render/baselines/particle_mode.h"
#include "render/core/renderer.h"
#include "render/instance_shadows.h"
#include "render/modes/scene_lattices.h"
#include "render/baselines/texture_mode.h"

namespace lat {

enum class RenderMode { kExact, kLattice, kAuto, kTexture, kParticles };

// How lattice mode with a filter finds the shadows its instances cast: shadow rays through
// their tables, or deep shadow maps traced through the same tables (render/instance_shadows.h).
enum class InstanceShadowing { kRays, kDeepMap };

struct ModeDescription {
    std::string_view name;
    RenderMode mode;
    std::string_view help;
    // Whether its render is dealt across the ranks of an MPI job; a mode that is not renders
    // on rank 0 alone (docs/distributed.md).
    bool spreads_over_ranks = false;
};

std::span<const ModeDescription> render_modes();
const ModeDescription& mode_description(RenderMode mode);

struct ModeSettings {
    int spp = 1;
    SamplerKind sampler = kDefaultSampler;  // exact, lattice and texture modes
    bool progress = false;
    std::string lattice_dir;  // empty: default_cache_dir()
    TableSpec spec;           // lattice mode
    LatticeFiltering filtering;  // lattice and auto modes; spread is set from the camera and spp
    // Exact mode: every instance answered by its own crossings of sub-rays across each ray's
    // footprint, partial coverage composited front to back (LatticePolicy::kFootprint).
    bool footprint = false;
    AccelOptions accel;
    TextureOptions texture;
    // Texels a side of each light's shadow map: particle mode's, or the deep maps'
    // (instance_shadows); 0: the mode's own default (the deep maps': a texel a camera sample's
    // footprint wide at the instances, InstanceShadows).
    int shadow_map_size = 0;
    InstanceShadowing instance_shadows = InstanceShadowing::kRays;
    // Collective, for a mode that spreads_over_ranks: tables built once by all ranks together
    // and read by each from the cache, tiles dealt across ranks, the image on rank 0.
    bool across_ranks = false;
    // Called once, when preparation (tables, maps, particles, acceleration) is done and the
    // render proper begins: `render` installs its interrupt handlers there, since table builds
    // do not poll for signals.
    std::function<void()> before_render;
};

struct ModeResult {
    RenderOutput out;
    double prepare_ms = 0;  // tables loaded or built, maps baked, particles made
    double build_ms = 0;    // the acceleration structures (exact and lattice modes; the deep
                            // shadow maps' base accelerator)
    double build_cpu_ms = 0;  // its CPU time, all threads
    // Bytes the mode adds to the scene without its instances: the instances' exact geometry
    // (primitive parts and one transform per instance), plus the tables in lattice mode; the
    // maps in texture mode; the particle buffer in particle mode.
    std::uint64_t bytes_added = 0;
    SceneLattices lattices;  // lattice and auto modes, and exact mode's footprint filtering
    // Deep shadow maps of the instances (InstanceShadowing::kDeepMap), when made (their bytes
    // are in bytes_added; their tiles were traced within the render's time).
    std::optional<ShadowMapReport> shadow_maps;
};

// Whether the mode answers instances by lattices (tables or sub-rays: SceneLattices) rather
// than tracing them as they are; footprint: exact mode's ModeSettings::footprint.
bool answers_instances(RenderMode mode, bool footprint);

ModeResult render_in_mode(const Scene& scene, RenderMode mode, const ModeSettings& settings);

}  // namespace lat
