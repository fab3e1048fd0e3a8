#include "lattice/encodings.h"

#include <cmath>
#include <stdexcept>

#include "lattice/candidates_table.h"
#include "lattice/dense_table.h"
#include "lattice/hash14_table.h"
#include "lattice/learned_table.h"
#include "lattice/perfect_table.h"
#include "util/error.h"

namespace lat {
namespace {

// Fingerprint bits of the perfect-hash encodings, -1 for the others.
int perfect_fingerprint_bits(const std::string& encoding) {
    for (const int bits : {0, 8, 16})
        if (encoding == PerfectTable::name(bits)) return bits;
    return -1;
}

}  // namespace

const std::vector<EncodingInfo>& table_encodings() {
    static const std::vector<EncodingInfo> list = {
        {"hash14", "the paper's hash table, 14-byte entries with key and overflow chain",
         Hash14Table::kMaxPoints, 15.0, true},
        {"dense",
         "no hashing: occupancy bits with a rank directory, both directions per record, "
         "bit widths chosen per table for the error targets",
         0xFFFFFFFFull, 4.0, true},
        {"candidates", "exact: per pair the parts a ray can meet, intersected exactly at render",
         0xFFFFFFFFull, 2.0, false},
        // Building holds the keys (8 bytes a hit) and those that collide at the first level.
        {"perfect5", "section 5.2.1: minimal perfect hash (BBHash), 5-byte entries, no keys",
         PerfectTable::kMaxPoints, 17.0, true},
        {"perfect6", "perfect5 with an 8-bit key fingerprint per entry (6 bytes)",
         PerfectTable::kMaxPoints, 18.0, true},
        {"perfect7", "perfect5 with a 16-bit key fingerprint per entry (7 bytes)",
         PerfectTable::kMaxPoints, 19.0, true},
        // Planned at the build's peak: the index of the hits by entry point (8 bytes per hit),
        // the exception list and the table (a few bytes per hit at most).
        {"learned",
         "a distance field fitted to the hits, marched along the pair, plus exceptions where "
         "it errs beyond the bounds",
         LearnedTable::kMaxPoints, 12.0, true},
    };
    return list;
}

const EncodingInfo& encoding_info(const std::string& name) {
    std::string known;
    for (const EncodingInfo& e : table_encodings()) {
        if (e.name == name) return e;
        known += (known.empty() ? "" : ", ") + e.name;
    }
    throw InputError("unknown table encoding '" + name + "' (known: " + known + ")");
}

ByteBuffer encode_table(const std::string& encoding, const RasterizeResult& r,
                        const TableContext& ctx, const EncodeOptions& opt) {
    if (encoding == "hash14") return Hash14Table::build(r.raw);
    if (encoding == "dense") return DenseTable::build(r.raw, ctx, opt);
    if (encoding == "candidates") return CandidatesTable::build(ctx, false);
    if (const int fp = perfect_fingerprint_bits(encoding); fp >= 0)
        return PerfectTable::build(r.raw, fp);
    if (encoding == "learned") return LearnedTable::build(r.raw, ctx, opt);
    throw std::invalid_argument("encode_table: unknown encoding " + encoding);
}

double hit_error_bound(const std::string& encoding, const TableContext& ctx,
                       const EncodeOptions& opt) {
    if (encoding == "candidates") return 0.0;  // exact hits on the real ray
    if (encoding == "hash14") {                // t rounded to 1/65535 of a segment
        const double diagonal = std::hypot(ctx.cells[0], ctx.cells[1], ctx.cells[2]) * ctx.cell;
        return diagonal / 65535.0;
    }
    if (encoding == "dense" || encoding == "learned") return opt.max_point_error * ctx.sigma;
    return kInfinity;  // perfect hashes answer missing keys with some stored hit
}

std::unique_ptr<LatticeTable> open_table(const std::string& encoding, const std::uint8_t* payload,
                                         std::size_t size, std::uint64_t entries,
                                         const TableContext& ctx) {
    if (encoding == "hash14") return std::make_unique<Hash14Table>(payload, size, entries);
    if (encoding == "dense") return std::make_unique<DenseTable>(payload, size, entries, ctx);
    if (encoding == "candidates")
        return std::make_unique<CandidatesTable>(payload, size, entries, ctx);
    if (const int fp = perfect_fingerprint_bits(encoding); fp >= 0)
        return std::make_unique<PerfectTable>(payload, size, entries, fp);
    if (encoding == "learned") return std::make_unique<LearnedTable>(payload, size, entries, ctx);
    throw std::runtime_error("unknown table encoding '" + encoding + "'");
}

}  // namespace lat
