#include "distributed/timeline.h"

#include <chrono>

namespace lat::dist {
namespace {

using Clock = std::chrono::steady_clock;
// Static initialisation: before main(), so the timeline includes MPI_Init.
const Clock::time_point g_start = Clock::now();
Timeline g_timeline{};

}  // namespace

void mark(Step step) {
    g_timeline[static_cast<std::size_t>(step)] =
        std::chrono::duration<double, std::milli>(Clock::now() - g_start).count();
}

Timeline timeline() { return g_timeline; }

std::string_view step_name(Step step) {
    constexpr std::array<std::string_view, static_cast<std::size_t>(Step::kCount)> names{
        "joined", "loaded", "checked", "tables", "accel", "dealt", "gathered", "encoded"};
    return names[static_cast<std::size_t>(step)];
}

}  // namespace lat::dist
