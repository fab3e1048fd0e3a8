// lattice inspect FILE.lht [--json] [--no-certify]: what a table holds, and its certified error.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "lattice/boundary_grid.h"
#include "lattice/certify.h"
#include "lattice/encoding.h"
#include "lattice/table_file.h"
#include "scene/table_metadata.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/progress.h"

namespace lat::cli {
namespace {

struct InspectArgs {
    std::string file;
    bool json = false, certify = true;
    int threads = 0;
};

int run_inspect(const InspectArgs& a) {
    const ThreadLimit limit(a.threads);
    const TableHeader h = read_table_header(a.file);
    const Primitive prim = primitive_from_metadata(h, a.file);
    const LoadedTable t = load_table_file(a.file, nullptr, prim.shape.get());
    const double per_hit = h.entries ? double(t.bytes) / double(h.entries) : 0.0;
    const Encoding& encoding = find_encoding(h.encoding);  // known: the file loaded
    nlohmann::json j = {{"file", a.file},
                        {"encoding", h.encoding},
                        {"encoding_summary", encoding.summary},
                        {"primitive", prim.name},
                        {"cells", h.cells},
                        {"sigma", h.sigma},
                        {"sigma_inv", h.sigma_inv},
                        {"N_lp", h.pairs},
                        {"stored_hits", h.entries},
                        {"bytes", t.bytes},
                        {"bytes_per_stored_hit", per_hit}};
    if (!a.json) {
        std::printf("%s: %s table of primitive '%s', %d x %d x %d cells (sigma %g, sigma^-1 %d)\n",
                    a.file.c_str(), h.encoding.c_str(), prim.name.c_str(), h.cells[0], h.cells[1],
                    h.cells[2], h.sigma, h.sigma_inv);
        std::printf("  N_lp %llu, %llu stored hits, %s (%llu bytes), %.3f bytes per stored hit\n",
                    static_cast<unsigned long long>(h.pairs), static_cast<unsigned long long>(h.entries),
                    human_bytes(double(t.bytes)).c_str(),
                    static_cast<unsigned long long>(t.bytes), per_hit);
        std::printf("  %.*s\n", static_cast<int>(encoding.summary.size()), encoding.summary.data());
        if (!t.table->details().empty()) std::printf("  %s\n", t.table->details().c_str());
    }
    j["details"] = t.table->details();
    if (const double pairs = static_cast<double>(BoundaryGrid::pair_count(h.cells));
        a.certify && pairs > kMaxCertifyPairs) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      ": certifying would re-intersect %.3g point pairs, more than the limit of "
                      "%.3g (use --no-certify)",
                      pairs, kMaxCertifyPairs);
        throw InputError(a.file + buf);
    }
    if (a.certify) {
        const CertifyReport r = certify_table(*t.table, h.context(prim.shape.get()), !a.json && ProgressBar::stderr_is_terminal());
        j["certified"] = {{"pairs", r.pairs},
                          {"exact_hits", r.exact_hits},
                          {"false_hits", r.false_hits},
                          {"false_misses", r.false_misses},
                          {"max_point_error_sigma", r.max_point_error},
                          {"mean_point_error_sigma", r.mean_point_error},
                          {"max_normal_error_deg", r.max_normal_error_deg},
                          {"mean_normal_error_deg", r.mean_normal_error_deg},
                          {"seconds", r.seconds}};
        if (!a.json) {
            std::printf("  certified against exact re-intersection of all %llu pairs (%.1f s):\n",
                        static_cast<unsigned long long>(r.pairs), r.seconds);
            std::printf("    point error  max %.6f sigma, mean %.6f sigma\n", r.max_point_error,
                        r.mean_point_error);
            std::printf("    normal error max %.4f deg, mean %.4f deg\n", r.max_normal_error_deg,
                        r.mean_normal_error_deg);
            std::printf("    false hits %llu, false misses %llu (of %llu exact hits)\n",
                        static_cast<unsigned long long>(r.false_hits),
                        static_cast<unsigned long long>(r.false_misses),
                        static_cast<unsigned long long>(r.exact_hits));
        }
    }
    if (a.json) std::printf("%s\n", j.dump(2).c_str());
    return 0;
}

}  // namespace

Command add_inspect_command(CLI::App& parent) {
    auto args = std::make_shared<InspectArgs>();
    Command c;
    c.app = parent.add_subcommand(
        "inspect", "Describe a lattice table and certify its error against exact intersection");
    c.app->add_option("file", args->file, "Table file (.lht)")->required();
    c.app->add_flag("--json", args->json, "Machine-readable output");
    c.app->add_flag("!--no-certify", args->certify, "Skip the (exhaustive) error certification");
    c.app->add_option("--threads", args->threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(0, 4096));
    c.run = [args] { return run_inspect(*args); };
    return c;
}

}  // namespace lat::cli
