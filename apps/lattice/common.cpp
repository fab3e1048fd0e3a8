#include "commands.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace lat::cli {

void add_table_options(CLI::App& app, TableSpec& spec) {
    app.add_option("--sigma-inv", spec.sigma_inv,
                   "Refine the lattice K times: K x the cells at sigma / K, same box")
        ->check(CLI::Range(1, 1 << 20));
    std::string names;
    for (const EncodingInfo& e : table_encodings()) names += (names.empty() ? "" : ", ") + e.name;
    app.add_option("--encoding", spec.encoding, "Lattice table encoding: " + names);
    app.add_option("--max-point-error", spec.options.max_point_error,
                   "Quantising encodings: largest point error, in units of sigma")
        ->check(CLI::PositiveNumber);
    app.add_option("--max-normal-error", spec.options.max_normal_error_deg,
                   "Quantising encodings: largest normal error, in degrees")
        ->check(CLI::PositiveNumber);
    app.add_option("--dense-normals", spec.options.normals,
                   "dense: normals as octahedral codes (oct), as the part hit, re-evaluated "
                   "(part), or whichever is smaller (auto)")
        ->check(CLI::IsMember({"auto", "oct", "part"}));
}

std::unique_ptr<tbb::global_control> limit_threads(int n) {
    if (n <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 static_cast<std::size_t>(n));
}

void write_json_file(const std::string& path, const nlohmann::json& j) {
    AtomicFile out(path);  // a unique temporary: concurrent writers of one path never collide
    const std::string text = j.dump(2) + "\n";
    out.write(text.data(), text.size());
    out.commit();
}

}  // namespace lat::cli
