#pragma once
// The `lattice` subcommands. Each adds its options to the app and returns the action that runs
// when it is chosen; actions return the process exit code and report user errors by throwing
// lat::InputError (exit code 2). Under mpirun every rank parses the command line; a command
// that runs across ranks is run by every rank, any other by rank 0 alone.
#include <functional>

namespace CLI {
class App;
}

namespace lat::cli {

struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
    bool across_ranks = false;  // render and rasterize (docs/distributed.md)
};

Command add_render_command(CLI::App& parent);
Command add_rasterize_command(CLI::App& parent);
Command add_table1_command(CLI::App& parent);
Command add_compare_command(CLI::App& parent);
Command add_inspect_command(CLI::App& parent);
Command add_scatter_command(CLI::App& parent);
Command add_table2_command(CLI::App& parent);

}  // namespace lat::cli
