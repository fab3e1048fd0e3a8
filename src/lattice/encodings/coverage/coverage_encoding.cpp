#include <cmath>

#include "lattice/encoding.h"
#include "lattice/encodings/coverage/coverage_table.h"

namespace lat {

// The build's memory estimate below counts the samples at this size.
static_assert(sizeof(CoverageSample) == 24);

extern const Encoding kCoverageEncoding;
const Encoding kCoverageEncoding{
    .name = "coverage",
    .summary = "prefiltered: per ordered pair its hit and its coverage (share of the rays "
               "snapping to it that meet the primitive, their mean hit), for --filter",
    // A point's tile on a face then fits the 24 bits pair_index.h gives it, and the slots
    // (about N^2: the valid pairs and the tiles' padding) stay few enough to index.
    .max_points = 0xFFFFull,
    // While building: the rasterized hit (20 bytes), about 1.5 coverage samples of 24 bytes, and
    // the records (10 bytes, up to twice that with the empty slots of their groups), per stored
    // hit.
    .bytes_per_hit = 78.0,
    .needs_hits = true,
    .coverage = true,
    // 4: 4-byte coverage records with the normals' spread; 3: without it; 2: 8-byte ones,
    // pairs filed by face pair in tiles (pair_index.h); 1: a * N + b
    .layout = 4,
    .build = &CoverageTable::build,
    .open = [](const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
               const TableContext& ctx) -> std::unique_ptr<LatticeTable> {
        return std::make_unique<CoverageTable>(payload, size, entries, ctx);
    },
    // The hits of the pairs' own segments are kept as hash14 keeps them: t in 1/65534 of a
    // segment no longer than the box's diagonal.
    .error_bound = [](const TableContext& ctx, const EncodeOptions&) {
        return std::hypot(ctx.cells[0], ctx.cells[1], ctx.cells[2]) * ctx.cell / 65534.0;
    },
};

}  // namespace lat
