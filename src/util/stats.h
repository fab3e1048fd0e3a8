#pragma once
// Counters any module may bump while it works, read by whoever reports them (the renderer's
// --stats): each thread keeps its own tallies, so a bump is one increment with no contention
// and no atomics, and a reader takes the growth of its own thread's tally over a stretch of
// work it ran there (a tile). Counters report what happened; nothing may steer by them.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace lat::stats {

enum class Counter : std::size_t {
    // Snaps of a ray to a lattice's grid point pair: one per call of a lattice shape's
    // intersect, occluded, spans or inside.
    kLatticeVisits,
    kCount
};

// Every counter's value at once: a thread's tally, or what a stretch of work added to them.
using Tally = std::array<std::uint64_t, std::size_t(Counter::kCount)>;

// The counter's name in reports (render --stats, per rank).
constexpr std::string_view counter_name(Counter c) {
    switch (c) {
        case Counter::kLatticeVisits: return "lattice_visits";
        case Counter::kCount: break;
    }
    return "";
}

namespace detail {
inline constinit thread_local Tally t_tally{};
}  // namespace detail

inline void bump(Counter c) {
    ++detail::t_tally[std::size_t(c)];
}
// The calling thread's tally of c so far.
inline std::uint64_t this_thread(Counter c) {
    return detail::t_tally[std::size_t(c)];
}
// All of the calling thread's tallies so far.
inline const Tally& this_thread() { return detail::t_tally; }

}  // namespace lat::stats
