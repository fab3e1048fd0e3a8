#pragma once
// The `lattice` subcommands. Each adds its options to the app and returns the action that runs
// when it is chosen; actions return the process exit code and report user errors by throwing
// lat::InputError (exit code 2).
#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <tbb/global_control.h>

#include "scene/lattice_tables.h"

namespace lat::cli {

struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

Command add_render_command(CLI::App& parent);
Command add_rasterize_command(CLI::App& parent);
Command add_table1_command(CLI::App& parent);
Command add_compare_command(CLI::App& parent);
Command add_inspect_command(CLI::App& parent);

// --sigma-inv, --encoding and the encodings' error targets, shared by render and rasterize.
void add_table_options(CLI::App& app, TableSpec& spec);

// Caps oneTBB (and so Embree's builds) at n threads for the object's lifetime; 0 = all cores.
std::unique_ptr<tbb::global_control> limit_threads(int n);
// Writes JSON atomically (temporary + rename); throws InputError naming the path.
void write_json_file(const std::string& path, const nlohmann::json& j);

}  // namespace lat::cli
