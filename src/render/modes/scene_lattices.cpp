#include "render/modes/scene_lattices.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <map>

#include "csg/csg_shape.h"
#include "geometry/lattice_source.h"
#include "lattice/boundary_grid.h"
#include "lattice/coverage.h"
#include "lattice/encoding.h"
#include "lattice/lattice_shape.h"
#include "util/error.h"

namespace lat {
namespace {

// Shadow rays leaving a surface seen at a slant are wider than the camera's footprint there;
// sub-rays as wide as the camera's footprint times this bound, no wider: wider sub-rays make wider
// culling boxes (their reach), and those cost more than the shadows gain, since the accelerator
// calls back for every box a ray meets and the boxes of dense fur overlap. 1.25 gained up to
// 0.2 dB over 1 for up to 16 % more time; 2 gained under 0.3 dB more for up to 56 % more
// (bench/notes/filtering-constants.md).
constexpr double kSubRayWidening = 1.25;


// The levels j (sigma^-1 = K 2^j) a primitive's instances need: from the level whose cell
// matches the widest footprint to that of the narrowest.
std::pair<int, int> lod_range(const Scene& scene, int prim, const TableContext& base, double spread) {
    const auto [narrowest, widest] = footprint_range(scene, prim, base, spread);
    if (!(narrowest <= widest)) return {0, 0};
    const double lo = lod_level(base.cell, widest), hi = lod_level(base.cell, narrowest);
    const int j0 = std::clamp(static_cast<int>(std::floor(lo)), 0, kMaxLodLevels - 1);
    // A level needed only a quarter of the way to the next is left to its coarser neighbour:
    // the finer table is 4 times the memory for a sliver of blend.
    const int j1 = std::clamp(static_cast<int>(std::ceil(hi - 0.25)), j0, kMaxLodLevels - 1);
    return {j0, j1};
}

// Level j of a primitive's levels of detail: sigma^-1 = K 2^j.
TablePlan level_plan(const Scene& scene, const Primitive& p, const TableSpec& spec, int j) {
    TableSpec level = spec;
    level.sigma_inv = spec.sigma_inv << j;
    return plan_table(p, level, scene.file);
}

// What a primitive's levels of detail cost: pairs and the time to build them.
struct LevelCosts {
    const Scene& scene;
    const Primitive& p;
    const TableSpec& spec;
    double cost = p.shape ? std::max(1.0, ShapeSource(*p.shape).intersect_cost()) : 1.0;  // per sub-ray

    long long sigma_inv(int j) const { return static_cast<long long>(spec.sigma_inv) << j; }
    std::string name(int j) const { return "sigma^-1 = " + std::to_string(sigma_inv(j)); }
    double pairs(int j) const {
        return static_cast<double>(
            BoundaryGrid::pair_count(level_plan(scene, p, spec, j).context.cells));
    }
    // LatticeFiltering::max_work: the coverage build's estimate (coverage_work), once a level.
    double work(int j) const {
        const auto [it, added] = works.try_emplace(j, 0.0);
        if (added) {
            const TableContext ctx = level_plan(scene, p, spec, j).context;
            it->second = ctx.primitive ? coverage_work(ctx) : pairs(j) * cost;
        }
        return it->second;
    }
    mutable std::map<int, double> works = {};
};

// The levels j to read, of those the footprints want: within the largest refinement and the
// pair budget (memory), and the finest affordable (time): within the work budget, or cached
// already (the budget bounds what a render builds, not what it reads). Level 0, the lattice
// asked for, is read whatever its size.
// The budget is the render's (kLodBudgetMinutes): left is what the primitives before have not
// spent; the levels chosen would spend `cost` of it, finest first, which the caller takes only
// if they are read (auto mode answers a primitive over budget by its crossings instead).
struct LevelChoice {
    std::pair<int, int> range;
    int fitting = 0;           // the finest level wanted within the size limits
    bool over_budget = false;  // range.second < fitting: a finer level past the work budget
    double spent_before = 0;   // of the budget, by the primitives before
    double cost = 0;           // of the budget, by building the levels in range
};
LevelChoice choose_levels(const LevelCosts& c, const TableCache& cache, std::pair<int, int> wanted,
                          const LatticeFiltering& filtering, double left) {
    const auto fits = [&](int j) {
        return c.sigma_inv(j) <= kMaxSigmaInv && c.pairs(j) <= filtering.max_pairs;
    };
    // What building level j would spend: nothing when it is cached.
    const auto cost = [&](int j) {
        return cache.cached(level_plan(c.scene, c.p, c.spec, j)) ? 0.0 : c.work(j);
    };
    // Level 0, the lattice asked for, is read whatever it costs.
    const auto affordable = [&](int j) {
        const double w = cost(j);
        return j == 0 || w == 0 || w <= left;
    };
    const double spent_before = filtering.max_work - left, budget = left;
    int fitting = 0;
    while (fitting < wanted.second && fits(fitting + 1)) ++fitting;
    int finest = fitting;
    while (!affordable(finest)) --finest;
    left -= cost(finest);
    int first = finest;
    while (first > std::min(wanted.first, finest) && affordable(first - 1)) left -= cost(--first);
    return {{first, finest}, fitting, finest < fitting, spent_before, budget - left};
}

// What the user should know of a choice that leaves out levels wanted: which, why, and what
// serves their rays instead (by_crossings: the primitive's crossings). Empty when none is.
std::string levels_note(const LevelCosts& c, std::pair<int, int> wanted, const LevelChoice& ch,
                        const LatticeFiltering& filtering, bool by_crossings) {
    const auto number = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, v < 10 ? "%.2g" : "%.0f", v);
        return std::string(text);
    };
    const auto [first, finest] = ch.range;
    std::string why, instead = "rays that want finer read " + c.name(finest);
    if (ch.over_budget) {
        const double minutes = lod_minutes(c.work(ch.fitting));
        const double spent = lod_minutes(ch.spent_before);
        why = c.name(ch.fitting) + " would take about " + number(minutes) +
              " minutes of one core to build, over --lod-budget " +
              number(lod_minutes(filtering.max_work)) +
              (spent > 0 ? " (" + number(spent) + " of it spent on the primitives before)" : "") +
              " (--lod-budget " + std::to_string(static_cast<long long>(std::ceil(minutes + spent))) +
              " builds it once, for every later render)";
    } else if (finest < wanted.second && c.sigma_inv(finest + 1) > kMaxSigmaInv) {
        why = c.name(finest + 1) + " is past the largest, " + std::to_string(kMaxSigmaInv);
    } else if (finest < wanted.second) {
        why = c.name(finest + 1) + " has " + number(c.pairs(finest + 1) / 1e6) +
              " M pairs, over the budget of " + number(filtering.max_pairs / 1e6) + " M";
    } else if (first > wanted.first) {
        why = c.name(first - 1) + " is over --lod-budget and not in the cache";
        instead = "rays that want coarser read " + c.name(first);
    } else {
        return "";
    }
    if (by_crossings)
        instead = "its rays take its own crossings instead (" + std::to_string(kSubRays) +
                  " sub-rays a ray)";
    const std::string asked = wanted.first == wanted.second
                                  ? "level of detail " + c.name(wanted.first)
                                  : "levels of detail from " + c.name(wanted.first) + " to " +
                                        c.name(wanted.second);
    return located_message(c.scene.file, c.p.where,
                           asked + " wanted; " + why + "; " + instead);
}

// For a primitive answered by its crossings: each instance's bound on its sub-rays' footprint
// (out.widest_footprints), and the widest of them, the shape's.
double sub_ray_bounds(const Scene& scene, int prim, const TableContext& base, double spread,
                      SceneLattices& out) {
    double widest = 0;
    if (out.widest_footprints.empty()) out.widest_footprints.assign(scene.object_count(), kInfinity);
    for (std::size_t i = 0; i < out.widest_footprints.size(); ++i) {
        if (scene.primitive_of(i) != prim) continue;
        out.widest_footprints[i] =
            kSubRayWidening * instance_footprints(scene, scene.transform(i), base, spread).second;
        widest = std::max(widest, out.widest_footprints[i]);
    }
    return widest;
}

// One level's table from the cache, counted in out's totals and in the answer's levels.
std::shared_ptr<const LatticeTable> read_table(const TableCache& cache, const TablePlan& plan,
                                               bool progress, SceneLattices& out,
                                               PrimitiveAnswer& answer) {
    const bool coverage = plan.encoding->coverage && plan.context.primitive;
    const double estimate =
        coverage && !cache.cached(plan) ? coverage_cpu_seconds(plan.context) : 0.0;
    const TableCache::Entry e = cache.get(plan, progress);
    out.table_bytes += e.bytes;
    out.table_entries += e.table->entries();
    out.built += e.built ? 1 : 0;
    out.build_seconds += e.build_seconds;
    if (e.built)
        out.builds.push_back({plan.primitive->name, plan.header.sigma_inv,
                              coverage ? plan.context.coverage_rays : 0, e.build_seconds, estimate});
    if (coverage) answer.coverage_rays = plan.context.coverage_rays;
    out.paths.push_back(e.path);
    answer.sigma_inv.push_back(std::llround(plan.context.sigma / plan.context.cell));
    return e.table;
}

// A primitive's lattice answered through a footprint, as planned (lattice/answer_plan.h): its
// levels from the cache, coarse to fine, or its own crossings of sub-rays. base: the lattice
// asked for.
//   A primitive answered by its own crossings reads its table only as a CSG leaf (spans,
// `inside`), and only in auto mode: the lattice asked for serves it there, and elsewhere no
// table is loaded or built. On each instance its sub-rays, and so its culling, span at most
// kSubRayWidening times the widest footprint of the camera's pixels on that instance
// (AccelObject::widest_footprint); the shape's own bound is the widest over its instances.
void filtered_lattice(const Scene& scene, int prim, const TableCache* cache, const TableSpec& spec,
                      bool progress, const LatticeFiltering& filtering, const TableContext& base,
                      const AnswerQuery& q, AnswerPlan plan, double& budget_left,
                      SceneLattices& out, PrimitiveAnswer& answer) {
    const Primitive& p = scene.primitives[static_cast<std::size_t>(prim)];
    std::pair<int, int> range{0, 0};
    if (q.lod && plan.by == AnsweredBy::kFilteredTables) {
        const LevelCosts costs{scene, p, spec};
        const std::pair<int, int> wanted = lod_range(scene, prim, base, filtering.spread);
        assert(cache);  // every policy but kFootprint reads tables
        const LevelChoice choice = choose_levels(costs, *cache, wanted, filtering, budget_left);
        if (choice.over_budget) plan_past_budget(q, base.primitive, plan);
        const bool by_crossings = plan.by == AnsweredBy::kSubRayCrossings;
        if (!by_crossings) range = choice.range, budget_left -= choice.cost;
        const std::string note = levels_note(costs, wanted, choice, filtering, by_crossings);
        if (!note.empty()) out.notes.push_back(note);
    }
    answer.why = plan.why;
    if (plan.exact_shape) return;
    const bool by_crossings = plan.by == AnsweredBy::kSubRayCrossings;
    const double sub_ray_width =
        by_crossings ? sub_ray_bounds(scene, prim, base, filtering.spread, out) : 0;
    answer.by = plan.by;
    if (!by_crossings) answer.encoding = spec.encoding;
    std::vector<FilterLevel> levels;
    double error = 0;
    if (!plan.reads_tables) levels.push_back({nullptr, base});
    PrimitiveAnswer csg_tables;  // tables read for CSG alone are not how instances are answered
    for (int j = range.first; plan.reads_tables && j <= range.second; ++j) {
        const TablePlan level = level_plan(scene, p, spec, j);
        assert(cache);
        PrimitiveAnswer& counted = by_crossings ? csg_tables : answer;
        levels.push_back({read_table(*cache, level, progress, out, counted), level.context});
        error = level.error_bound();
    }
    out.shapes[static_cast<std::size_t>(prim)] = footprint_shape(
        plan, std::move(levels), filtering.filter, error, std::max(0.0, sub_ray_width));
}

}  // namespace

std::pair<double, double> instance_footprints(const Scene& scene, const Transform& xf,
                                              const TableContext& base, double spread) {
    const Bounds3 box{{0, 0, 0}, Vec3{double(base.cells[0]), double(base.cells[1]),
                                      double(base.cells[2])} * base.cell};
    const Bounds3 wb = xf.bounds(box);
    const double r = 0.5 * length(wb.extent());
    const double d = length(wb.center() - scene.camera.eye);
    // Object units per world unit along a ray (rigid or uniformly scaled instances).
    const double scale = 1 / std::cbrt(length(xf.vector({1, 0, 0})) *
                                       length(xf.vector({0, 1, 0})) *
                                       length(xf.vector({0, 0, 1})));
    return {std::max(d - r, 1e-9) * spread * scale, (d + r) * spread * scale};
}

std::pair<double, double> footprint_range(const Scene& scene, int prim, const TableContext& base,
                                          double spread) {
    double lo = kInfinity, hi = -kInfinity;
    for (std::size_t i = 0; i < scene.object_count(); ++i) {
        if (scene.primitive_of(i) != prim) continue;
        const auto [near, far] = instance_footprints(scene, scene.transform(i), base, spread);
        lo = std::min(lo, near);
        hi = std::max(hi, far);
    }
    return {lo, hi};
}

SceneLattices scene_lattices(const Scene& scene, const TableCache* cache, const TableSpec& spec,
                             bool progress, const LatticeFiltering& filtering) {
    SceneLattices out;
    out.shapes.resize(scene.primitives.size());
    // Instances, at the top level or as CSG leaves.
    std::vector<bool> used(scene.primitives.size(), false), csg_leaf(used), instanced(used);
    for (const ScatterGroup& g : scene.scatters)
        if (!g.placements.empty())
            used[static_cast<std::size_t>(g.primitive)] = instanced[static_cast<std::size_t>(g.primitive)] = true;
    for (const SceneObject& o : scene.objects) {
        if (o.primitive >= 0) used[static_cast<std::size_t>(o.primitive)] = instanced[static_cast<std::size_t>(o.primitive)] = true;
        if (o.shape)
            for (const int p : csg_leaf_primitives(*o.shape))
                used[static_cast<std::size_t>(p)] = csg_leaf[static_cast<std::size_t>(p)] = true;
    }
    const bool sub_rays = filtering.policy == LatticePolicy::kFootprint;
    // (Footprint filtering sets the smooth filter and reads no table: its spec is only a frame.)
    assert(!sub_rays || filtering.filter != LatticeFilter::kNone);
    if (!sub_rays && filtering.filter != LatticeFilter::kNone &&
        !find_encoding(spec.encoding).coverage)
        throw InputError("--filter: filtered lattices need a table encoding that stores coverage "
                         "(--encoding coverage), not '" + spec.encoding + "'");
    assert(sub_rays || cache);
    double budget_left = filtering.max_work;  // the render's, spent by the levels built
    for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
        if (!used[i]) continue;
        const Primitive& p = scene.primitives[i];
        PrimitiveAnswer answer;
        answer.primitive = p.name;
        answer.where = p.where;
        const AnswerQuery q{filtering.policy, filtering.filter,
                            filtering.lod && filtering.spread > 0, p.lattice.has_value(),
                            instanced[i], csg_leaf[i]};
        TableContext base;  // the lattice asked for, once the plan asks for the primitive
        const AnswerPlan how = plan_answer(q, [&] {
            base = plan_table(p, spec, scene.file).context;
            return base.primitive;
        });
        if (how.by == AnsweredBy::kExact) {
            answer.by = how.by;
            answer.why = how.why;
        } else if (how.by != AnsweredBy::kTable) {
            filtered_lattice(scene, static_cast<int>(i), cache, spec, progress, filtering, base, q,
                             how, budget_left, out, answer);
        } else {
            const TablePlan plan = plan_table(p, spec, scene.file);
            answer.encoding = spec.encoding;
            out.shapes[i] = make_lattice_shape(read_table(*cache, plan, progress, out, answer),
                                               plan.context, plan.error_bound());
        }
        if (instanced[i]) out.answers.push_back(std::move(answer));
    }
    return out;
}

}  // namespace lat
