#pragma once
// Rasterization (paper 2.1): for every ordered pair (p_i, p_o) of grid points on different
// faces of the lattice box, the intersection of the segment p_i -> p_o with the primitive that
// is closest to p_i. Parallel over entry points; the result does not depend on thread (or
// rank) count.
#include <array>
#include <cstdint>
#include <vector>

#include "geometry/shape.h"
#include "lattice/table.h"

namespace lat {

struct RasterizeOptions {
    bool keep_hits = true;  // false: only count (Table 1)
    // Keep the hits as PointHits (every point id must be below 0xFFFF) instead of RawHits:
    // for encodings that store no more (Encoding::stream_points). Not with across_ranks in a
    // job of several ranks, whose messages carry raw hits.
    bool point_hits = false;
    bool progress = false;
    // Trace only every n-th entry point (to estimate a table's size before building it).
    std::uint32_t entry_stride = 1;
    // Collective: the blocks of entry points are dealt across the ranks of the MPI job
    // (distributed/deal.h) and the hits gathered on rank 0, whose result is then the same as a single
    // process's; the other ranks' results hold the counts of their own blocks, and no hits.
    bool across_ranks = false;
};

struct RasterizeResult {
    std::uint64_t pairs_eq2 = 0;         // N_lp by the paper's eq. (2)
    std::uint64_t pairs_enumerated = 0;  // N_lp by enumeration, counted as eq. (2) counts
    std::uint64_t pairs_traced = 0;      // distinct (p_i, p_o) segments considered
    std::uint64_t hits = 0;              // distinct segments that hit (table entries)
    std::uint64_t hits_counted = 0;      // N_ix, counted as the paper counts N_lp
    std::uint64_t tests = 0;             // exact segment-part tests performed
    double seconds = 0;
    // With across_ranks: this rank's own share (segments traced, hits); else the same as above.
    std::uint64_t pairs_traced_here = 0, hits_here = 0;
    // When keep_hits, in entry point order, the same for any thread count: raw, or points
    // with point_hits.
    RawHits raw;
    PointHits points;
};

// The lattice and the primitive (which must be set) are ctx's.
RasterizeResult rasterize(const TableContext& ctx, const RasterizeOptions& opt = {});

}  // namespace lat
