#pragma once
// Dealing the items 0..n-1 of a parallel loop (image tiles, blocks of entry points) to the
// threads of this process, or of every rank of the job.
#include <cstdint>
#include <functional>
#include <vector>

namespace lat {
class ProgressBar;
}

namespace lat::dist {

struct DealOptions {
    // Collective: spread the items over every rank of the job, in chunks that shrink as the
    // items run out (guided self-scheduling), dealt by rank 0 and run by each rank on all its
    // threads (how and why: docs/distributed.md, "Dealing"). False (and in a single process):
    // one oneTBB loop over all items here.
    bool across_ranks = false;
    ProgressBar* progress = nullptr;  // one unit per item; on rank 0 it counts every rank's
};

// Items [begin, end).
struct Chunk {
    std::uint32_t begin = 0, end = 0;
};

// What this rank did.
struct DealReport {
    std::vector<Chunk> chunks;  // in the order dealt
    std::uint64_t items = 0;
    int threads = 0;
    double seconds = 0;       // from the first item dealt to the last one done here
    double wait_seconds = 0;  // threads' time waiting for a chunk, summed over threads
};

// work(i) must be safe to run on several threads at once, for different i.
DealReport deal(std::uint32_t n, const std::function<void(std::uint32_t)>& work,
                const DealOptions& options = {});

}  // namespace lat::dist
