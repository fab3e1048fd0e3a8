// `lattice`: one binary, several subcommands (render, rasterize, table1, compare, inspect, scatter).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <new>
#include <vector>

#include "commands.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/interrupt.h"

int main(int argc, char** argv) {
    CLI::App app{"lattice: ray tracing with three-dimensional lattice textures"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "lattice 0.1.0");

    std::vector<lat::cli::Command> commands;
    commands.push_back(lat::cli::add_render_command(app));
    commands.push_back(lat::cli::add_rasterize_command(app));
    commands.push_back(lat::cli::add_table1_command(app));
    commands.push_back(lat::cli::add_compare_command(app));
    commands.push_back(lat::cli::add_inspect_command(app));
    commands.push_back(lat::cli::add_scatter_command(app));

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // Usage errors are user errors: one line, exit code 2.
        std::fprintf(stderr, "lattice: error: %s (see lattice --help)\n", e.what());
        return 2;
    }
    try {
        for (auto& c : commands)
            if (c.app->parsed()) return c.run();
    } catch (const lat::Interrupted& e) {
        lat::remove_temp_files();  // the unwinding removed ours already; this is belt and braces
        std::fprintf(stderr, "lattice: %s\n", e.what());
        return e.exit_code();
    } catch (const lat::InputError& e) {
        std::fprintf(stderr, "lattice: error: %s\n", e.what());
        return 2;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "lattice: error: out of memory\n");
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "lattice: internal error: %s\n", e.what());
        return 1;
    }
    return 2;
}
