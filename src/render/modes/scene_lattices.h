#pragma once
// Lattice mode: the lattice shape of every primitive a scene's instances use, from the table
// cache (built on demand).
#include <memory>
#include <string_view>
#include <string>
#include <vector>

#include "lattice/cache/table_cache.h"
#include "lattice/answer_plan.h"
#include "lattice/coverage.h"
#include "scene/scene.h"

namespace lat {

// What answers one primitive, and why, for the summary line and --stats.
struct PrimitiveAnswer {
    std::string primitive;  // its name in the scene
    std::string where;      // e.g. "primitives.hair"
    AnsweredBy by = AnsweredBy::kTable;
    std::string encoding;              // of the tables read; empty for sub-rays
    std::vector<long long> sigma_inv;  // the levels read, coarse to fine; empty for sub-rays
    int coverage_rays = 0;             // of its filtered tables, sub-rays a pair; else 0
    std::string why;                   // how the mode chose (auto mode), else empty
};

struct SceneLattices {
    std::vector<std::shared_ptr<const Shape>> shapes;  // per primitive; null: its own shape
    // Per object: the widest footprint (object units) its rays are traced with, for instances
    // of primitives answered by sub-rays (AccelObject::widest_footprint); else infinity. Empty
    // when no primitive is answered by sub-rays (every one infinity).
    std::vector<double> widest_footprints;
    std::uint64_t table_bytes = 0;
    std::uint64_t table_entries = 0;
    int built = 0;
    double build_seconds = 0;
    // Each table built, for the summary line and --stats.
    struct Built {
        std::string primitive;
        long long sigma_inv = 0;
        int coverage_rays = 0;  // prefiltered tables; else 0
        double seconds = 0;
        double estimated_cpu_seconds = 0;  // the level budget's estimate (prefiltered tables)
    };
    std::vector<Built> builds;
    std::vector<std::string> paths;
    std::vector<PrimitiveAnswer> answers;  // per instanced primitive, in scene order
    // What the user should know about the lattices chosen: levels of detail left out for a
    // budget, and what serves their rays instead.
    std::vector<std::string> notes;
};

// How lattices are filtered: the filter, and whether levels of detail are built. With
// lod, each primitive gets the levels sigma^-1 = K 2^j whose cells match the footprints of the
// camera's pixels (spread: a pixel's angle) somewhere on its instances, at most kMaxLodLevels;
// a primitive its plan answers by its crossings (lattice/answer_plan.h: answered_by_primitive,
// or levels wanted past the work budget, below) is answered so and gets the lattice asked for alone, only if a CSG tree holds a
// copy (no ray reads it elsewhere).
// Levels of detail beyond sigma^-1 = K are built only up to kMaxLodPairs ordered pairs of
// boundary points: rays that want finer get the finest level within it, not a table that takes
// half an hour to build. 2^27 holds the hair of Plates 4 and 5 at 4K (111 M pairs); a CSG ring
// of 16 x 16 x 8 cells (`lattice-rings`, before its torus was answered by its crossings) stopped
// at 2K (17 M pairs; 4K, 268 M pairs, was still building after 7 minutes in 5 GB).
inline constexpr double kMaxLodPairs = 134217728.0;
// They are also built only within a work budget (LatticeFiltering::max_work) of simple tests,
// the coverage builds' estimate (lattice/coverage.h: coverage_work, which counts the table's
// sub-rays a pair and is calibrated in CPU seconds by kCoverageTestsPerCpuSecond), so that the
// budget is minutes of one core (`render --lod-budget`). The budget is the render's: every
// level it builds, of every primitive (in scene order), the lattice asked for included, spends
// from it; a level in the cache is read whatever the budget, and costs nothing. Ten minutes of
// one core: a cold render builds for at most about 5 minutes on 2 cores (the builds keep both
// busy). The levels of the benchmarks' fur take seconds to a minute; a CSG of quartics at 512^2
// (the burr, 16 sub-rays a pair) about 5 minutes at its finest level.
inline constexpr double kLodBudgetMinutes = 10;
// The work budget of so many minutes of one core, and back.
constexpr double lod_work(double minutes) { return minutes * 60 * kCoverageTestsPerCpuSecond; }
constexpr double lod_minutes(double work) { return work / (60 * kCoverageTestsPerCpuSecond); }
inline constexpr double kMaxLodWork = lod_work(kLodBudgetMinutes);
struct LatticeFiltering {
    LatticeFilter filter = LatticeFilter::kNone;
    bool lod = false;
    double spread = 0;
    double max_pairs = kMaxLodPairs;
    double max_work = kMaxLodWork;
    LatticePolicy policy = LatticePolicy::kAuto;
};
// Three levels, K to 4K: the next (8K) of the paper's hair would take 28 GB to build.
inline constexpr int kMaxLodLevels = 3;

// The narrowest and widest footprints (primitive units; spread: a pixel's angle) of the
// camera's pixels on a primitive's instances, at the nearest and farthest points of their
// lattice boxes (base: the lattice asked for). Empty (first > second) when it has no instance
// of its own (only in CSG).
std::pair<double, double> footprint_range(const Scene& scene, int prim, const TableContext& base,
                                          double spread);
// The same for one instance.
std::pair<double, double> instance_footprints(const Scene& scene, const Transform& xf,
                                              const TableContext& base, double spread);

// With filtering, spec's encoding must store coverage (Encoding::coverage; else InputError).
// cache may be null only for LatticePolicy::kFootprint, which reads no table.
SceneLattices scene_lattices(const Scene& scene, const TableCache* cache, const TableSpec& spec,
                             bool progress, const LatticeFiltering& filtering = {});
inline SceneLattices scene_lattices(const Scene& scene, const TableCache& cache,
                                    const TableSpec& spec, bool progress,
                                    const LatticeFiltering& filtering = {}) {
    return scene_lattices(scene, &cache, spec, progress, filtering);
}

}  // namespace lat
