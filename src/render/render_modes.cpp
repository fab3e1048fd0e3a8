#include "render/render_modes.h"

#include <array>
#include <algorithm>
#include <chrono>
#include <optional>
#include <cmath>

#include "distributed/timeline.h"
#include "geometry/chain.h"
#include "lattice/encoding.h"
#include "render/core/camera.h"
#include "render/instance_shadows.h"
#include "render/modes/integrators.h"
#include "render/baselines/scene_parts.h"
#include "util/memory.h"

namespace lat {
namespace {

constexpr std::array<ModeDescription, 5> kModes{{
    {"exact", RenderMode::kExact,
     "full ray trace of every primitive (with --footprint on, instances by sub-rays across each "
     "pixel's footprint)",
     true},
    {"lattice", RenderMode::kLattice,
     "every instance answered from its lattice tables (built on first use and cached)", true},
    {"auto", RenderMode::kAuto,
     "per primitive: sub-rays across the footprint for one cheap to intersect, filtered tables "
     "for a costlier one; the summary line names each choice",
     true},
    {"texture", RenderMode::kTexture,
     "instances replaced by colour, coverage and normal maps baked on the surface they grow from"},
    {"particles", RenderMode::kParticles,
     "instances as streams of particles splatted in screen space (Kajiya-Kay, shadow maps)"},
}};

// The instances' exact geometry: every used primitive's parts once, one transform each.
std::uint64_t instance_geometry_bytes(const Scene& scene) {
    std::uint64_t bytes = 0;
    std::vector<bool> counted(scene.primitives.size(), false);
    for (const std::size_t i : instance_objects(scene)) {
        std::size_t in_group = i;
        bytes += scene.group_of(in_group) ? sizeof(Affine) : sizeof(Transform);
        const auto p = static_cast<std::size_t>(scene.primitive_of(i));
        if (counted[p]) continue;
        counted[p] = true;
        if (const auto& s = scene.primitives[p].shape; const ChainShape* c = s ? as_chain(*s) : nullptr)
            bytes += c->spheres().size() * sizeof(ChainSphere) + c->cylinders().size() * sizeof(ChainCylinder);
    }
    return bytes;
}

// How the mode answers instances: the one place a mode becomes a LatticePolicy. None for exact
// mode without footprint filtering (instances traced as they are).
std::optional<LatticeFiltering> lattice_policy(const Scene& scene, RenderMode mode,
                                               const ModeSettings& settings) {
    if (!answers_instances(mode, settings.footprint)) return std::nullopt;
    LatticeFiltering f = settings.filtering;
    switch (mode) {
        case RenderMode::kExact:
            f.policy = LatticePolicy::kFootprint;
            f.filter = LatticeFilter::kSmooth;
            f.lod = true;
            break;
        case RenderMode::kLattice: f.policy = LatticePolicy::kTables; break;
        case RenderMode::kAuto: f.policy = LatticePolicy::kAuto; break;
        default: return std::nullopt;
    }
    f.spread = PinholeCamera(scene.camera, settings.spp).spread();
    return f;
}

// Lattice mode's deep shadow maps, made into `maps` when asked for and there is something to
// map (instances, lights, shadows); the time of their base accelerator is r's build time.
void make_instance_shadows(const TracedScene& rs, const LatticeFiltering& filtering,
                           const ModeSettings& settings,
                           const TracedScene::InstanceShapeFn& instance_shape,
                           const AccelOptions& accel, std::optional<InstanceShadows>& maps,
                           ModeResult& r) {
    const Scene& scene = rs.scene();
    // Maps of tables only: sheets of sub-rays (auto mode's cheap primitives, exact mode's
    // footprint) want a shadow ray's own footprint (bench/notes/scale-log.md).
    if (filtering.policy != LatticePolicy::kTables || !scene.shadows || scene.lights.empty() ||
        settings.instance_shadows != InstanceShadowing::kDeepMap)
        return;
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    if (const Bounds3 target = instance_bounds(rs); !target.empty())
        maps.emplace(rs, target, instance_shape, accel, settings.shadow_map_size, filtering.spread);
    r.build_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.build_cpu_ms += (cpu_seconds() - cpu0) * 1e3;
}

}  // namespace

bool answers_instances(RenderMode mode, bool footprint) {
    return mode == RenderMode::kLattice || mode == RenderMode::kAuto ||
           (mode == RenderMode::kExact && footprint);
}

std::span<const ModeDescription> render_modes() { return kModes; }

const ModeDescription& mode_description(RenderMode mode) {
    for (const ModeDescription& d : kModes)
        if (d.mode == mode) return d;
    return kModes.front();
}

ModeResult render_in_mode(const Scene& scene, RenderMode mode, const ModeSettings& settings) {
    using clock = std::chrono::steady_clock;
    auto ms_since = [](clock::time_point t) {
        return std::chrono::duration<double, std::milli>(clock::now() - t).count();
    };
    ModeResult r;
    RenderOptions opt;
    opt.spp = settings.spp;
    opt.sampler = settings.sampler;
    opt.progress = settings.progress;
    opt.across_ranks = settings.across_ranks && mode_description(mode).spreads_over_ranks;
    auto t0 = clock::now();
    switch (mode) {
        case RenderMode::kExact:
        case RenderMode::kLattice:
        case RenderMode::kAuto: {
            r.bytes_added = instance_geometry_bytes(scene);
            const std::optional<LatticeFiltering> filtering = lattice_policy(scene, mode, settings);
            if (filtering) {
                std::optional<TableCache> cache;
                if (filtering->policy != LatticePolicy::kFootprint)
                    cache.emplace(settings.lattice_dir.empty() ? default_cache_dir() : settings.lattice_dir,
                                  opt.across_ranks);
                // Sub-rays read no table: the lattice box at sigma^-1 = 1 frames their culling.
                const TableSpec spec = cache ? settings.spec : TableSpec{1, std::string(coverage_encoding().name), {}};
                r.lattices = scene_lattices(scene, cache ? &*cache : nullptr, spec,
                                            settings.progress, *filtering);
                r.bytes_added += r.lattices.table_bytes;
            }
            TracedScene::InstanceShapeFn instance_shape;
            if (filtering)
                instance_shape = [&](int prim) {
                    const auto i = static_cast<std::size_t>(prim);
                    return r.lattices.shapes[i] ? r.lattices.shapes[i] : scene.primitives[i].shape;
                };
            r.prepare_ms = ms_since(t0);
            dist::mark(dist::Step::kTables);
            t0 = clock::now();
            const double cpu0 = cpu_seconds();
            AccelOptions accel = settings.accel;
            accel.progress = settings.progress;
            const TracedScene rs(scene, instance_shape, accel, r.lattices.widest_footprints);
            r.build_ms = ms_since(t0);
            r.build_cpu_ms = (cpu_seconds() - cpu0) * 1e3;
            // Partial hits are traced in layers, chosen here once: a filter makes them
            // (footprint filtering's is smooth); point-sampled tables and exact shapes have none.
            const bool layered = filtering && filtering->filter != LatticeFilter::kNone;
            std::optional<InstanceShadows> maps;
            if (layered) make_instance_shadows(rs, *filtering, settings, instance_shape, accel, maps, r);
            dist::mark(dist::Step::kAccel);
            if (settings.before_render) settings.before_render();
            r.out = layered ? render_layered(rs, opt, maps ? &*maps : nullptr) : render_exact(rs, opt);
            if (maps) {
                r.shadow_maps = maps->report();
                r.bytes_added += r.shadow_maps->bytes;
            }
            break;
        }
        case RenderMode::kTexture: {
            TextureOptions to = settings.texture;
            to.progress = settings.progress;
            const TextureMaps maps = bake_texture(scene, to);
            r.prepare_ms = ms_since(t0);
            r.bytes_added = maps.bytes();
            if (settings.before_render) settings.before_render();
            r.out = render_texture(scene, maps, opt);
            break;
        }
        case RenderMode::kParticles: {
            const ParticleSet set = make_particles(scene);
            r.prepare_ms = ms_since(t0);
            r.bytes_added = set.bytes();
            ParticleOptions po;
            po.spp = settings.spp;
            po.progress = settings.progress;
            if (settings.shadow_map_size > 0) po.shadow_map_size = settings.shadow_map_size;
            if (settings.before_render) settings.before_render();
            r.out = render_particles(scene, set, po);
            break;
        }
    }
    return r;
}

}  // namespace lat
