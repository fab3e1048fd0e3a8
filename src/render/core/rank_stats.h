#pragma once
// A render dealt across the ranks of an MPI job (distributed/deal.h): each rank's share of the
// figures, and the gathers that bring the ranks' tiles and figures to rank 0.
#include <cstdint>
#include <span>
#include <vector>

#include "distributed/deal.h"
#include "distributed/timeline.h"
#include "util/stats.h"

namespace lat {

struct RankStats {
    int rank = 0;
    char host[64] = {};
    int threads = 0;
    std::uint32_t tiles = 0, chunks = 0;
    double render_ms = 0;  // first tile dealt to last tile done here
    double wait_ms = 0;    // threads' time waiting for tiles, summed
    double cpu_ms = 0;     // the process's CPU time (all threads) over the render and gather
    std::uint64_t primary_rays = 0, shadow_rays = 0;
    stats::Tally counted{};  // what the stats counters (util/stats.h) added here
    std::uint64_t peak_memory_bytes = 0;
    dist::Timeline timeline{};  // when each step ended here
};

// The image's tiles as the ranks deal them: `width` x `height` pixels in tiles of `tile`
// pixels a side, row by row.
struct TileGrid {
    int width = 0, height = 0, tile = 0;
    int tiles_x() const { return (width + tile - 1) / tile; }
    int tiles_y() const { return (height + tile - 1) / tile; }
};

// Collective: rank 0 receives every other rank's tiles (`mine`: the chunks this rank rendered)
// of the RGB images `radiance` and `display`, which it holds whole; each message is checked
// before it is copied (every tile from exactly one rank; dist::MessageError otherwise).
void gather_tiles(const TileGrid& grid, const dist::DealReport& mine, std::span<float> radiance,
                  std::span<std::uint8_t> display);

// Collective: every rank's figures, on rank 0 (elsewhere empty), `mine` this rank's.
std::vector<RankStats> gather_rank_stats(const dist::DealReport& deal, RankStats mine);

}  // namespace lat
