#include "render/render_modes.h"

#include <array>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "dist/timeline.h"
#include "geometry/chain.h"
#include "render/scene_parts.h"

namespace lat {
namespace {

constexpr std::array<ModeDescription, 4> kModes{{
    {"exact", RenderMode::kExact, "full ray trace of every primitive", "full ray trace", "high", "slow",
     "medium", true},
    {"lattice", RenderMode::kLattice, "instances through their lattice tables (built on first use and cached)",
     "lattice", "high", "moderate", "large", true},
    {"texture", RenderMode::kTexture,
     "instances replaced by colour, coverage and normal maps baked on the surface they grow from",
     "texture mapping", "low", "very fast", "small"},
    {"particles", RenderMode::kParticles,
     "instances as streams of particles splatted in screen space (Kajiya-Kay, shadow maps)",
     "particle system", "medium", "fast", "small"},
}};

// The instances' exact geometry: every used primitive's parts once, one transform each.
std::uint64_t instance_geometry_bytes(const Scene& scene) {
    std::uint64_t bytes = 0;
    std::vector<bool> counted(scene.primitives.size(), false);
    for (const std::size_t i : instance_objects(scene)) {
        bytes += sizeof(Transform);
        const auto p = static_cast<std::size_t>(scene.objects[i].primitive);
        if (counted[p]) continue;
        counted[p] = true;
        if (const auto* c = dynamic_cast<const ChainShape*>(scene.primitives[p].shape.get()))
            bytes += c->spheres().size() * sizeof(ChainSphere) + c->cylinders().size() * sizeof(ChainCylinder);
    }
    return bytes;
}

}  // namespace

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
    opt.progress = settings.progress;
    opt.across_ranks = settings.across_ranks && mode_description(mode).spreads_over_ranks;
    auto t0 = clock::now();
    switch (mode) {
        case RenderMode::kExact:
        case RenderMode::kLattice: {
            RenderScene::InstanceShapeFn instance_shape;
            r.bytes_added = instance_geometry_bytes(scene);
            if (mode == RenderMode::kLattice) {
                const TableCache cache(settings.lattice_dir.empty() ? default_cache_dir() : settings.lattice_dir,
                                       opt.across_ranks);
                LatticeFiltering filtering = settings.filtering;
                // A pixel's angle, narrowed by the samples that share it.
                filtering.spread = 2 * std::tan(scene.camera.fov_y_deg * M_PI / 360.0) /
                                   scene.camera.height / std::sqrt(double(std::max(1, settings.spp)));
                r.lattices = scene_lattices(scene, cache, settings.spec, settings.progress, filtering);
                opt.layered = filtering.filter != LatticeFilter::kNone;
                instance_shape = [&r](int prim) { return r.lattices.shapes[static_cast<std::size_t>(prim)]; };
                r.bytes_added += r.lattices.table_bytes;
            }
            r.prepare_ms = ms_since(t0);
            dist::mark(dist::Step::kTables);
            t0 = clock::now();
            const RenderScene rs(scene, instance_shape, settings.accel,
                                 r.lattices.widest_footprints);
            r.build_ms = ms_since(t0);
            dist::mark(dist::Step::kAccel);
            if (settings.before_render) settings.before_render();
            r.out = render_image(rs, opt);
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
            po.shadow_map_size = settings.shadow_map_size;
            if (settings.before_render) settings.before_render();
            r.out = render_particles(scene, set, po);
            break;
        }
    }
    return r;
}

}  // namespace lat
