#include "lattice/cache/table_spec.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "lattice/coverage.h"
#include "util/error.h"
#include "util/hash.h"

namespace lat {

void check_sigma_inv(long long k, const std::string& where) {
    if (const std::string e = sigma_inv_error(k); !e.empty()) throw InputError(where + ": " + e);
}

namespace {

std::string normals_name(DenseNormals n) {
    for (const auto& [name, value] : kDenseNormalNames)
        if (value == n) return std::string(name);
    return {};
}

}  // namespace

TablePlan plan_table(const Primitive& p, const TableSpec& spec, const std::string& scene_file) {
    TablePlan plan;
    plan.primitive = &p;
    plan.place = located_message(scene_file, p.where, "");
    if (!p.lattice)
        throw InputError(plan.place + "primitive '" + p.name +
                         "' has no lattice (add \"lattice\": {\"sigma\": ..., \"cells\": [...]})");
    check_sigma_inv(spec.sigma_inv, "--sigma-inv");
    try {
        plan.encoding = &find_encoding(spec.encoding);
    } catch (const InputError& e) {
        throw InputError(std::string("--encoding: ") + e.what());
    }
    plan.options = spec.options;

    TableHeader& h = plan.header;
    h.encoding = plan.encoding->name;
    h.sigma = p.lattice->sigma;
    h.sigma_inv = spec.sigma_inv;
    h.cell = p.lattice->sigma / spec.sigma_inv;
    for (std::size_t a = 0; a < 3; ++a) {
        const long long n = static_cast<long long>(p.lattice->cells[a]) * spec.sigma_inv;
        h.cells[a] = static_cast<int>(std::min<long long>(n, 0x7FFFFFFF));
    }
    Fingerprint f;
    f.add(p.fingerprint)
        .add(h.sigma)
        .add(h.cells[0])
        .add(h.cells[1])
        .add(h.cells[2])
        .add(spec.sigma_inv)
        .add(h.encoding)
        .add(spec.options.max_point_error)
        .add(spec.options.max_normal_error_deg)
        .add(normals_name(spec.options.normals))
        .add(kRasterizerVersion);
    // Layout 1 is left out: the tables of the encodings whose payload never changed keep their
    // names.
    if (plan.encoding->layout != 1) f.add(plan.encoding->layout);
    // A prefiltered table's sub-rays a pair: tables of different counts never share a name. The
    // usual count is left out, so that the tables sampled with it keep theirs.
    if (plan.encoding->coverage && p.shape) h.coverage_rays = coverage_rays_for(*p.shape);
    if (h.coverage_rays != kCoverageRays) f.add(std::string("coverage rays")).add(h.coverage_rays);
    h.fingerprint = f.value();
    h.metadata = nlohmann::json{{"primitive", p.name},
                                {"definition", nlohmann::json::parse(p.definition)},
                                {"scene", scene_file}}
                     .dump();
    plan.context = h.context(p.shape.get());
    return plan;
}

}  // namespace lat
