#pragma once
// Lattice mode: the lattice shape of every primitive a scene's instances use, from the table
// cache (built on demand).
#include <memory>
#include <string>
#include <vector>

#include "lattice/cache/table_cache.h"
#include "scene/scene.h"

namespace lat {

struct SceneLattices {
    std::vector<std::shared_ptr<const Shape>> shapes;  // per primitive; null if unused
    std::uint64_t table_bytes = 0;
    std::uint64_t table_entries = 0;
    int built = 0;
    double build_seconds = 0;
    std::vector<std::string> paths;
};

SceneLattices scene_lattices(const Scene& scene, const TableCache& cache, const TableSpec& spec,
                             bool progress);

}  // namespace lat
