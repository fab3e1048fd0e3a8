#include "lattice/encoding.h"
#include "lattice/encodings/candidates/candidates_table.h"

namespace lat {

extern const Encoding kCandidatesEncoding;
const Encoding kCandidatesEncoding{
    .name = "candidates",
    .summary = "exact: per pair the parts a ray can meet, intersected exactly at render",
    .kind = LatticeTable::Kind::kCandidates,
    .max_points = 0xFFFFFFFFull,
    .bytes_per_hit = 2.0,
    .needs_hits = false,
    // 2: CAND3, whose lists name a CSG primitive's leaves (Pieces::piece_count).
    .layout = 2,
    .build = [](const RawHits&, const TableContext& ctx, const EncodeOptions& opt) {
        return CandidatesTable::build(ctx, false, opt.memory_budget);
    },
    .open = [](const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
               const TableContext& ctx) -> std::unique_ptr<LatticeTable> {
        return std::make_unique<CandidatesTable>(payload, size, entries, ctx);
    },
    .error_bound = [](const TableContext&, const EncodeOptions&) {
        return 0.0;  // exact hits on the real ray
    },
};

}  // namespace lat
