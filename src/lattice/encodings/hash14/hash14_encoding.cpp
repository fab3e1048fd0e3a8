#include <cmath>

#include "lattice/encoding.h"
#include "lattice/encodings/hash14/hash14_table.h"

namespace lat {

extern const Encoding kHash14Encoding;
const Encoding kHash14Encoding{
    .name = "hash14",
    .summary = "the paper's hash table, 14-byte entries with key and overflow chain",
    .max_points = Hash14Table::kMaxPoints,
    .bytes_per_hit = 15.0,
    .build = [](const RawHits& hits, const TableContext&, const EncodeOptions&) {
        return Hash14Table::build(hits);
    },
    .stream = [](RawHits&& hits, const TableContext&, const EncodeOptions&, PayloadSink& sink) {
        Hash14Table::write(std::move(hits), sink);
    },
    .stream_points = [](PointHits&& hits, const TableContext&, const EncodeOptions&,
                        PayloadSink& sink) { Hash14Table::write(std::move(hits), sink); },
    .open = [](const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
               const TableContext&) -> std::unique_ptr<LatticeTable> {
        return std::make_unique<Hash14Table>(payload, size, entries);
    },
    // t is rounded to 1/65535 of a segment, and no segment is longer than the box's diagonal.
    .error_bound = [](const TableContext& ctx, const EncodeOptions&) {
        return std::hypot(ctx.cells[0], ctx.cells[1], ctx.cells[2]) * ctx.cell / 65535.0;
    },
};

}  // namespace lat
