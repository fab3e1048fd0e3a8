#include "lattice/answer_plan.h"

#include <cmath>

#include "geometry/chain.h"
#include "geometry/lattice_source.h"
#include "lattice/sub_ray_shape.h"

namespace lat {
namespace {

// Why auto mode answers a primitive by its sub-rays (answered_by_primitive).
std::string cheap_reason(const Shape& primitive) {
    const double cost = ShapeSource(primitive).intersect_cost();
    if (cost <= kMaxExactCost)
        return "cheap to intersect: " + std::to_string(static_cast<long long>(std::ceil(cost))) +
               " simple tests, at most " + std::to_string(static_cast<int>(kMaxExactCost));
    return "a chain of spheres and cylinders: its sub-rays test only the parts near them";
}

// Which tables a plan through a footprint reads, and whether it leaves the exact shape.
void settle(const AnswerQuery& q, AnswerPlan& plan) {
    const bool sub_rays = plan.by == AnsweredBy::kSubRayCrossings;
    const bool everywhere = q.policy == LatticePolicy::kFootprint;
    plan.reads_tables = !sub_rays || (q.csg_leaf && !everywhere);
    plan.exact_shape = everywhere && !q.instanced;
}

}  // namespace

std::string_view answer_name(AnsweredBy by) {
    switch (by) {
        case AnsweredBy::kTable: return "table";
        case AnsweredBy::kFilteredTables: return "filtered tables";
        case AnsweredBy::kSubRayCrossings: return "sub-rays";
        case AnsweredBy::kExact: return "exact";
    }
    return "";
}

bool answered_by_primitive(const Shape& primitive) {
    return as_chain(primitive) != nullptr ||
           ShapeSource(primitive).intersect_cost() <= kMaxExactCost;
}

AnswerPlan plan_answer(const AnswerQuery& q, const std::function<const Shape*()>& primitive) {
    AnswerPlan plan;
    const bool everywhere = q.policy == LatticePolicy::kFootprint;
    if (everywhere && !q.has_lattice) {
        plan.by = AnsweredBy::kExact;
        plan.why = "it has no lattice box";
        return plan;
    }
    if (q.filter == LatticeFilter::kNone) return plan;  // its point-sampled table
    const Shape* prim = primitive();
    const bool cheap =
        q.policy == LatticePolicy::kAuto && q.lod && prim && answered_by_primitive(*prim);
    plan.by = everywhere || cheap ? AnsweredBy::kSubRayCrossings : AnsweredBy::kFilteredTables;
    if (cheap) plan.why = cheap_reason(*prim);
    settle(q, plan);
    return plan;
}

void plan_past_budget(const AnswerQuery& q, const Shape* primitive, AnswerPlan& plan) {
    if (q.policy != LatticePolicy::kAuto || !primitive) return;
    plan.by = AnsweredBy::kSubRayCrossings;
    plan.why = "its finer levels are over --lod-budget";
    settle(q, plan);
}

std::shared_ptr<const Shape> footprint_shape(const AnswerPlan& plan,
                                             std::vector<FilterLevel> levels, LatticeFilter filter,
                                             double table_error, double sub_ray_width) {
    const FilterLevel& finest = levels.back();
    // Without instances (only in CSG) it answers no ray: the tables read serve CSG alike.
    if (plan.by == AnsweredBy::kSubRayCrossings && sub_ray_width > 0 && finest.ctx.primitive)
        return std::make_shared<SubRayShape>(finest.ctx, finest.table, table_error, sub_ray_width);
    // A costly primitive's shadow rays read one pair each: its lookups, not its records, are
    // where the time goes.
    const bool costly = finest.ctx.primitive && !answered_by_primitive(*finest.ctx.primitive);
    return std::make_shared<FilteredLatticeShape>(std::move(levels), filter, table_error, costly);
}

}  // namespace lat
