#pragma once
// When each step of a command ended on this rank, in ms since the process started: --stats
// lists every rank's, to show where a distributed job spends its time (docs/distributed.md).
#include <array>
#include <cstddef>
#include <string_view>

namespace lat::dist {

enum class Step : int {
    kJoined,    // MPI_Init done (0 without MPI)
    kLoaded,    // scene loaded and agreed on
    kChecked,   // rasterize: the table checked for size
    kTables,    // render: lattice tables ready
    kAccel,     // render: acceleration structure built
    kDealt,     // the last dealt item (tile, block) done here
    kGathered,  // results gathered on rank 0
    kEncoded,   // rasterize: the table encoded and written (rank 0)
    kCount
};

// Milliseconds since start, per step; 0 = not reached.
using Timeline = std::array<double, static_cast<std::size_t>(Step::kCount)>;

void mark(Step step);
Timeline timeline();
std::string_view step_name(Step step);

}  // namespace lat::dist
