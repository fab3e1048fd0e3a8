#include "common.h"


#include <CLI/CLI.hpp>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "lattice/cache/table_spec.h"
#include "dist/job.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/file.h"
#include "util/hash.h"

namespace lat::cli {

const std::map<std::string, LatticeFilter>& lattice_filters() {
    static const std::map<std::string, LatticeFilter> filters = [] {
        std::map<std::string, LatticeFilter> m;
        for (const auto& [name, value] : kLatticeFilterNames) m.emplace(name, value);
        return m;
    }();
    return filters;
}

void add_table_options(CLI::App& app, TableSpec& spec) {
    // Its range is checked where the table is planned (plan_table), the one place for it.
    app.add_option("--sigma-inv", spec.sigma_inv,
                   "Refine the lattice K times: K x the cells at sigma / K, same box (1 to " +
                       std::to_string(kMaxSigmaInv) + ")");
    std::string names;
    for (const Encoding* e : encodings()) names += (names.empty() ? "" : ", ") + std::string(e->name);
    app.add_option("--encoding", spec.encoding, "Lattice table encoding: " + names);
    app.add_option("--max-point-error", spec.options.max_point_error,
                   "Quantising encodings: largest point error, in units of sigma")
        ->check(CLI::PositiveNumber);
    app.add_option("--max-normal-error", spec.options.max_normal_error_deg,
                   "Quantising encodings: largest normal error, in degrees")
        ->check(CLI::PositiveNumber);
    std::map<std::string, DenseNormals> normals;
    for (const auto& [name, value] : kDenseNormalNames) normals.emplace(name, value);
    app.add_option_function<std::string>(
           "--dense-normals",
           [&spec, normals](const std::string& name) { spec.options.normals = normals.at(name); },
           "dense: normals as octahedral codes (oct), as the part hit, re-evaluated (part), or "
           "whichever is smaller (auto; octahedral where parts are quartics)")
        ->check(CLI::IsMember(normals));
}

void agree_on_scene(const std::string& scene_file) {
    if (!dist::distributed()) return;
    std::string bytes;
    dist::agree([&] { bytes = read_text_file(scene_file, "scene file"); });
    dist::agree_on(hash_bytes(bytes.data(), bytes.size()), scene_file + ": the scene file");
}

nlohmann::json timeline_json(const dist::Timeline& t) {
    nlohmann::json j = nlohmann::json::object();
    for (int s = 0; s < static_cast<int>(dist::Step::kCount); ++s)
        if (const double ms = t[static_cast<std::size_t>(s)]; ms > 0)
            j[std::string(dist::step_name(static_cast<dist::Step>(s)))] = ms;
    return j;
}

void write_json_file(const std::string& path, const nlohmann::json& j) {
    AtomicFile out(path);  // a unique temporary: concurrent writers of one path never collide
    const std::string text = j.dump(2) + "\n";
    out.write(text.data(), text.size());
    out.commit();
}

}  // namespace lat::cli
