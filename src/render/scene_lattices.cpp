#include "render/scene_lattices.h"

#include "csg/csg_shape.h"
#include "lattice/lattice_shape.h"

namespace lat {

SceneLattices scene_lattices(const Scene& scene, const TableCache& cache, const TableSpec& spec,
                             bool progress) {
    SceneLattices out;
    out.shapes.resize(scene.primitives.size());
    // Instances, at the top level or as CSG leaves.
    std::vector<bool> used(scene.primitives.size(), false);
    for (const SceneObject& o : scene.objects) {
        if (o.primitive >= 0) used[static_cast<std::size_t>(o.primitive)] = true;
        if (const auto* csg = dynamic_cast<const CsgShape*>(o.shape.get()))
            for (const int p : csg->leaf_primitives()) used[static_cast<std::size_t>(p)] = true;
    }
    for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
        if (!used[i]) continue;
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
