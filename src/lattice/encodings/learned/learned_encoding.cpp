#include "lattice/encoding.h"
#include "lattice/encodings/learned/learned_table.h"

namespace lat {

extern const Encoding kLearnedEncoding;
const Encoding kLearnedEncoding{
    .name = "learned",
    // Experimental: the paper's section 5.2.2 measured; its lookups and builds are the slowest.
    .summary = "experimental, section 5.2.2: a distance field fitted to the hits, marched along "
               "the pair, plus exceptions where it errs beyond the bounds",
    .max_points = LearnedTable::kMaxPoints,
    // At the build's peak: the index of the hits by entry point (8 bytes per hit), the
    // exception list and the table (a few bytes per hit at most).
    .bytes_per_hit = 12.0,
    .build = [](const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt) {
        return LearnedTable::build(hits, ctx, opt);
    },
    .open = [](const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
               const TableContext& ctx) -> std::unique_ptr<LatticeTable> {
        return std::make_unique<LearnedTable>(payload, size, entries, ctx);
    },
    .error_bound = [](const TableContext& ctx, const EncodeOptions& opt) {
        return opt.max_point_error * ctx.sigma;
    },
};

}  // namespace lat
