// `lattice`: one binary, several subcommands (render, rasterize, table1, compare, inspect, scatter,
// table2). Started by mpirun or srun it is one rank of a job (docs/distributed.md).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "distributed/job.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/hash.h"
#include "util/interrupt.h"

namespace {

// In an MPI job a failure that the ranks did not reach together (dist::agree) ends them all
// at once: the one that failed has printed why.
int fail(int code) {
    if (lat::dist::distributed()) lat::dist::abort_job(code);
    return code;
}

// Parses the command line on every rank; a usage error on any of them (all, usually) is one
// line from rank 0 and exit code 2 everywhere. Returns the exit code when there is nothing
// more to do (help, version).
std::optional<int> parse(CLI::App& app, int argc, char** argv) {
    std::exception_ptr answered;  // help or version asked for
    lat::dist::agree([&] {
        try {
            app.parse(argc, argv);
        } catch (const CLI::Success&) {
            answered = std::current_exception();
        } catch (const CLI::ParseError& e) {
            throw lat::InputError(std::string(e.what()) + " (see lattice --help)");
        }
    });
    if (!answered) return std::nullopt;
    try {
        std::rethrow_exception(answered);
    } catch (const CLI::Error& e) {
        return lat::dist::is_root() ? app.exit(e) : 0;
    }
}

std::uint64_t command_line_fingerprint(int argc, char** argv) {
    std::uint64_t h = 0;
    for (int i = 1; i < argc; ++i) h = lat::hash_bytes(argv[i], std::strlen(argv[i]) + 1, h);
    return h;
}

int run(int argc, char** argv) {
    CLI::App app{"lattice: ray tracing with three-dimensional lattice textures"};
    app.require_subcommand(1);
    app.set_version_flag("--version", lat::dist::built_with_mpi() ? "lattice 0.1.0 (with MPI)" : "lattice 0.1.0");

    std::vector<lat::cli::Command> commands;
    commands.push_back(lat::cli::add_render_command(app));
    commands.push_back(lat::cli::add_rasterize_command(app));
    commands.push_back(lat::cli::add_table1_command(app));
    commands.push_back(lat::cli::add_compare_command(app));
    commands.push_back(lat::cli::add_inspect_command(app));
    commands.push_back(lat::cli::add_scatter_command(app));
    commands.push_back(lat::cli::add_table2_command(app));

    try {
        if (const std::optional<int> code = parse(app, argc, argv)) return *code;
        for (auto& c : commands) {
            if (!c.app->parsed()) continue;
            if (!c.across_ranks && !lat::dist::is_root()) return 0;
            if (c.across_ranks) lat::dist::agree_on(command_line_fingerprint(argc, argv), "the command line");
            return c.run();
        }
    } catch (const lat::Interrupted& e) {
        lat::remove_temp_files();  // the unwinding removed ours already; this is belt and braces
        std::fprintf(stderr, "lattice: %s\n", e.what());
        return fail(e.exit_code());
    } catch (const lat::dist::JobInputError& e) {
        if (e.print_here()) std::fprintf(stderr, "lattice: error: %s\n", lat::message_line(e.what()).c_str());
        return 2;
    } catch (const lat::InputError& e) {
        std::fprintf(stderr, "lattice: error: %s\n", lat::message_line(e.what()).c_str());
        return fail(2);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "lattice: error: out of memory\n");
        return fail(3);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "lattice: internal error: %s\n", lat::message_line(e.what()).c_str());
        return fail(1);
    }
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    const lat::dist::Session session(argc, argv);
    return run(argc, argv);
}
