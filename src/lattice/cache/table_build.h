#pragma once
// Building a primitive's table file: the checks made before any long work, rasterizing,
// encoding and writing.
#include <string>

#include "lattice/cache/table_spec.h"
#include "lattice/rasterizer.h"

namespace lat {

// Throws InputError (naming the scene file and the primitive), before any long work, when the
// table cannot be built here: the primitive leaves its lattice box, the encoding cannot key
// that many points, or the table would not fit in memory (the message
// gives the size it would need).
void check_buildable(const TablePlan& plan);

struct TableBuild {
    TableHeader header;
    RasterizeResult raster;  // counts and timing (hits not kept)
    double encode_seconds = 0;
    std::uint64_t bytes = 0;  // the whole file
};

// Checks, rasterizes the primitive, encodes the table and writes it to `path` atomically.
// across_ranks (collective, in an MPI job): rank 0 checks, all ranks rasterize their share of
// the entry points, rank 0 encodes and writes; the other ranks' result holds their own counts
// only.
TableBuild build_table_file(const TablePlan& plan, const std::string& path, bool progress,
                            bool across_ranks = false);

}  // namespace lat
