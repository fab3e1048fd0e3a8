#pragma once
// How the rays of an instanced lattice primitive are answered: the one place that decides
// between its point-sampled table, its prefiltered tables (FilteredLatticeShape), its own
// crossings of sub-rays across each ray's footprint (SubRayShape) and its exact shape, and
// that makes the shape answering through a footprint. render/modes/scene_lattices.cpp gathers what
// the plan asks (the primitive, whether its levels fit the build budget, the tables) and
// follows it.
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "coverage/sub_rays.h"
#include "lattice/filtered_shape.h"

namespace lat {

// Who decides how instanced primitives are answered: the render mode (render/render_modes.h).
enum class LatticePolicy {
    kTables,   // lattice mode: every primitive by its tables, never its own crossings
    kAuto,     // auto mode: a primitive cheap to intersect by sub-rays, a costlier one by its
               // tables while the levels it wants are within the build budget
    kFootprint,  // exact mode with footprint filtering: every primitive by sub-rays, no table
};

// How an instanced primitive's rays are answered: the one list of the ways, as reported on the
// summary line and in --stats (answer_name).
enum class AnsweredBy {
    kTable,           // its point-sampled table (no filter), as rasterized
    kFilteredTables,  // its coverage tables, filtered, at the levels of detail read
    kSubRayCrossings, // its own exact crossings of sub-rays across each ray's footprint
    kExact,           // its own exact crossing of each ray (no lattice box to cull sub-rays by)
};
std::string_view answer_name(AnsweredBy by);

// Primitives other than chains whose exact intersection costs more than this many simple tests
// (LatticeSource::intersect_cost) are answered by their tables in auto mode, when the levels their
// footprints want are within the build budget: past it a sub-ray costs more than a table's
// blend of pairs, and the tables are ahead of exact mode at equal time
// (bench/notes/filtering-constants.md).
inline constexpr double kMaxExactCost = 64;
// Whether auto mode answers a primitive's rays from the primitive itself: a chain (spheres and
// cylinders: hairs, tufts) always, whatever its parts, since its sub-rays test only the parts
// near the ray, found through a tree of their boxes (PartBoxes); other shapes when they cost
// at most kMaxExactCost.
bool answered_by_primitive(const Shape& primitive);

// What the plan weighs for one primitive.
struct AnswerQuery {
    LatticePolicy policy = LatticePolicy::kAuto;
    LatticeFilter filter = LatticeFilter::kNone;
    bool lod = false;          // levels of detail, from the camera's footprints
    bool has_lattice = false;  // the primitive has a lattice box
    bool instanced = false;    // some object is an instance of it
    bool csg_leaf = false;     // some CSG tree holds an instance of it
};

struct AnswerPlan {
    AnsweredBy by = AnsweredBy::kTable;
    std::string why;  // how auto mode chose, else empty
    // Answered through a footprint (filtered tables or sub-rays), whether its tables are read:
    // its levels, or, answered by sub-rays, the lattice asked for alone as a CSG leaf (auto
    // mode; footprint filtering leaves a CSG leaf its exact shape).
    bool reads_tables = false;
    // No lattice shape at all: footprint filtering leaves a primitive found only in CSG its
    // own exact shape.
    bool exact_shape = false;
};

// The plan before the levels of detail are chosen. primitive(): the primitive's shape (from
// its lattice's table plan), asked only where the plan depends on it (null: none).
AnswerPlan plan_answer(const AnswerQuery& q, const std::function<const Shape*()>& primitive);

// Once the levels the footprints want are chosen (for a plan of filtered tables with levels of
// detail): in auto mode a primitive whose finer levels are past the build budget answers by its
// crossings instead, since tables coarser than its footprints blur it and cost more than finer
// ones, their sheets being wider and less opaque (bench/notes).
void plan_past_budget(const AnswerQuery& q, const Shape* primitive, AnswerPlan& plan);

// The shape answering a primitive through a footprint, as planned: by sub-rays (the one level
// given, its table, if read, for CSG; sub_ray_width its instances' widest footprint, 0 when it
// has none), else by the tables' levels.
std::shared_ptr<const Shape> footprint_shape(const AnswerPlan& plan,
                                             std::vector<FilterLevel> levels, LatticeFilter filter,
                                             double table_error, double sub_ray_width);

}  // namespace lat
