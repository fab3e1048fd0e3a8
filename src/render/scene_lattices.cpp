#include "render/scene_lattices.h"

#include <algorithm>
#include <cmath>

#include "csg/csg_shape.h"
#include "lattice/boundary_grid.h"
#include "lattice/encoding.h"
#include "lattice/lattice_shape.h"
#include "util/error.h"

namespace lat {
namespace {

// The levels j (sigma^-1 = K 2^j) a primitive's instances need: from the level whose cell
// matches the footprint at the farthest point of any instance's box to that at the nearest.
std::pair<int, int> lod_range(const Scene& scene, int prim, const TableContext& base, double spread) {
    const Vec3 eye = scene.camera.eye;
    const Bounds3 box{{0, 0, 0}, Vec3{double(base.cells[0]), double(base.cells[1]),
                                      double(base.cells[2])} * base.cell};
    double lo = kInfinity, hi = -kInfinity;
    for (const SceneObject& o : scene.objects) {
        if (o.primitive != prim) continue;
        const Bounds3 wb = o.xf.bounds(box);
        const double r = 0.5 * length(wb.extent());
        const double d = length(wb.center() - eye);
        // Object units per world unit along a ray (rigid or uniformly scaled instances).
        const double scale = 1 / std::cbrt(length(o.xf.vector({1, 0, 0})) *
                                           length(o.xf.vector({0, 1, 0})) *
                                           length(o.xf.vector({0, 0, 1})));
        for (const double dist : {std::max(d - r, 1e-9), d + r}) {
            const double level = lod_level(base.cell, dist * spread * scale);
            lo = std::min(lo, level), hi = std::max(hi, level);
        }
    }
    if (!(lo <= hi)) return {0, 0};  // only in CSG: no instance of its own
    const int j0 = std::clamp(static_cast<int>(std::floor(lo)), 0, kMaxLodLevels - 1);
    // A level needed only a quarter of the way to the next is left to its coarser neighbour:
    // the finer table is 4 times the memory for a sliver of blend.
    const int j1 = std::clamp(static_cast<int>(std::ceil(hi - 0.25)), j0, kMaxLodLevels - 1);
    return {j0, j1};
}

// A primitive's filtered lattice: its levels from the cache, coarse to fine.
void filtered_lattice(const Scene& scene, int prim, const TableCache& cache, const TableSpec& spec,
                      bool progress, const LatticeFiltering& filtering, SceneLattices& out) {
    const Primitive& p = scene.primitives[static_cast<std::size_t>(prim)];
    std::pair<int, int> range{0, 0};
    if (filtering.lod && filtering.spread > 0)
        range = lod_range(scene, prim, plan_table(p, spec, scene.file).context, filtering.spread);
    // Levels beyond the largest refinement or the pair budget are left out: the finest level
    // within both then serves, with the primitive's crossings for rays that want finer. Level 0
    // (the lattice asked for) is built whatever its size.
    const auto level_plan = [&](int j) {
        TableSpec level = spec;
        level.sigma_inv = spec.sigma_inv << j;
        return plan_table(p, level, scene.file);
    };
    const auto allowed = [&](int j) {
        return (static_cast<long long>(spec.sigma_inv) << j) <= kMaxSigmaInv &&
               BoundaryGrid::pair_count(level_plan(j).context.cells) <= filtering.max_pairs;
    };
    int finest = 0;
    while (finest < range.second && allowed(finest + 1)) ++finest;
    range = {std::min(range.first, finest), std::min(range.second, finest)};
    std::vector<FilterLevel> levels;
    double error = 0;
    for (int j = range.first; j <= range.second; ++j) {
        const TablePlan plan = level_plan(j);
        const TableCache::Entry e = cache.get(plan, progress);
        levels.push_back({e.table, plan.context});
        error = plan.error_bound();
        out.table_bytes += e.bytes;
        out.table_entries += e.table->entries();
        out.built += e.built ? 1 : 0;
        out.build_seconds += e.build_seconds;
        out.paths.push_back(e.path);
    }
    out.shapes[static_cast<std::size_t>(prim)] =
        std::make_shared<FilteredLatticeShape>(std::move(levels), filtering.filter, error,
                                               filtering.lod);
}

}  // namespace

SceneLattices scene_lattices(const Scene& scene, const TableCache& cache, const TableSpec& spec,
                             bool progress, const LatticeFiltering& filtering) {
    SceneLattices out;
    out.shapes.resize(scene.primitives.size());
    // Instances, at the top level or as CSG leaves.
    std::vector<bool> used(scene.primitives.size(), false);
    for (const SceneObject& o : scene.objects) {
        if (o.primitive >= 0) used[static_cast<std::size_t>(o.primitive)] = true;
        if (const auto* csg = dynamic_cast<const CsgShape*>(o.shape.get()))
            for (const int p : csg->leaf_primitives()) used[static_cast<std::size_t>(p)] = true;
    }
    if (filtering.filter != LatticeFilter::kNone && !find_encoding(spec.encoding).coverage)
        throw InputError("--filter: filtered lattices need a table encoding that stores coverage "
                         "(--encoding coverage), not '" + spec.encoding + "'");
    for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
        if (!used[i]) continue;
        if (filtering.filter != LatticeFilter::kNone) {
            filtered_lattice(scene, static_cast<int>(i), cache, spec, progress, filtering, out);
            continue;
        }
        const TablePlan plan = plan_table(scene.primitives[i], spec, scene.file);
        const TableCache::Entry e = cache.get(plan, progress);
        out.shapes[i] = make_lattice_shape(e.table, plan.context, plan.error_bound());
        out.table_bytes += e.bytes;
        out.table_entries += e.table->entries();
        out.built += e.built ? 1 : 0;
        out.build_seconds += e.build_seconds;
        out.paths.push_back(e.path);
    }
    return out;
}

}  // namespace lat
