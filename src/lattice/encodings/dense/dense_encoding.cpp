#include "lattice/encoding.h"
#include "lattice/encodings/dense/dense_table.h"

namespace lat {

extern const Encoding kDenseEncoding;
const Encoding kDenseEncoding{
    .name = "dense",
    .summary = "no hashing: occupancy bits with a rank directory, both directions per record, "
               "bit widths chosen per table for the error targets",
    .max_points = 0xFFFFFFFFull,
    .bytes_per_hit = 4.0,
    // 2: the payload as in 1; `auto` normals now octahedral for quartic parts.
    .layout = 2,
    .build = &DenseTable::build,
    .open = [](const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
               const TableContext& ctx) -> std::unique_ptr<LatticeTable> {
        return std::make_unique<DenseTable>(payload, size, entries, ctx);
    },
    .error_bound = [](const TableContext& ctx, const EncodeOptions& opt) {
        return opt.max_point_error * ctx.sigma;
    },
};

}  // namespace lat
