#pragma once
// The number of threads oneTBB (and so Embree's builds) may use in this process.
#include <memory>

namespace lat {

// Caps oneTBB at n threads for its lifetime; 0 = all cores. One at a time (the command's).
class ThreadLimit {
public:
    explicit ThreadLimit(int n);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;

    struct Impl;  // opaque

private:
    std::unique_ptr<Impl> impl_;
};

// For its lifetime, lifts the ThreadLimit in force (if any) to n threads (0 = all cores): for a
// step that one rank of an MPI job runs while the other ranks of its node wait asleep, their
// cores idle (dist::on_root_with_node_threads).
class WiderThreads {
public:
    explicit WiderThreads(int n);
    ~WiderThreads();
    WiderThreads(const WiderThreads&) = delete;
    WiderThreads& operator=(const WiderThreads&) = delete;

private:
    int previous_ = 0;
};

// The cores this process may run on (its affinity mask; under mpirun --bind-to core, one).
int core_count();
// The threads oneTBB may use here now: the limit in force, at most core_count().
int thread_count();

}  // namespace lat
