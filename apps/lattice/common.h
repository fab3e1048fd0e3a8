#pragma once
// What several subcommands share: the table options, the thread limit, JSON output files.
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include <vector>

#include "lattice/filtered_shape.h"
#include "render/render_request.h"  // OptionEntry, timeline_json
#include "util/threads.h"  // ThreadLimit, for the commands

namespace CLI {
class App;
}

namespace lat::cli {

// Adds the options of a table (render/render_request.h) to a command, writing into target.
template <class Target>
void add_entries(CLI::App& app, const std::vector<OptionEntry<Target>>& entries, Target& target);

// --sigma-inv, --encoding and the encodings' error targets, shared by render and rasterize.
void add_table_options(CLI::App& app, TableSpec& spec);

// The --filter values (render, table2): none, box, smooth.
const std::map<std::string, LatticeFilter>& lattice_filters();

// Collective in an MPI job: every rank must have read the same scene file (dist::agree_on).
void agree_on_scene(const std::string& scene_file);

// Writes JSON atomically (temporary + rename); throws InputError naming the path.
void write_json_file(const std::string& path, const nlohmann::json& j);

}  // namespace lat::cli
