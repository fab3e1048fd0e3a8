// lattice table1 FILE.json [--json] [--threads N]: the paper's Table 1, recomputed.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "scene/table1_file.h"
#include "util/progress.h"

namespace lat::cli {
namespace {

struct Table1Args {
    std::string file;
    bool json = false;
    int threads = 0;
};

int run_table1(const Table1Args& a) {
    const ThreadLimit limit(a.threads);
    const auto rows = compute_table1(a.file, !a.json && ProgressBar::stderr_is_terminal());
    if (a.json) std::printf("%s\n", table1_json(rows).dump(2).c_str());
    else std::printf("%s", table1_text(rows).c_str());
    return 0;
}

}  // namespace

Command add_table1_command(CLI::App& parent) {
    auto args = std::make_shared<Table1Args>();
    Command c;
    c.app = parent.add_subcommand(
        "table1", "Recompute the paper's Table 1 (N_lp, N_ix, N_ix:N_lp) beside its printed values");
    c.app->add_option("file", args->file, "Table 1 file, e.g. examples/table1.json")->required();
    c.app->add_flag("--json", args->json, "Machine-readable output");
    c.app->add_option("--threads", args->threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(0, 4096));
    c.run = [args] { return run_table1(*args); };
    return c;
}

}  // namespace lat::cli
