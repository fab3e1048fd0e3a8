#include "lattice/encodings.h"

#include <stdexcept>

#include "lattice/candidates_table.h"
#include "lattice/dense_table.h"
#include "lattice/hash14_table.h"
#include "util/error.h"

namespace lat {

const std::vector<EncodingInfo>& table_encodings() {
    static const std::vector<EncodingInfo> list = {
        {"hash14", "the paper's hash table, 14-byte entries with key and overflow chain",
         Hash14Table::kMaxPoints, 15.0, true},
        {"dense", "no hashing: occupancy bits with a rank directory, both directions per record, "
                  "bit widths chosen per table for the error targets",
         0xFFFFFFFFull, 4.0, true},
        {"candidates", "exact: per pair the parts a ray can meet, intersected exactly at render",
         0xFFFFFFFFull, 2.0, false},
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
    throw std::invalid_argument("encode_table: unknown encoding " + encoding);
}

std::unique_ptr<LatticeTable> open_table(const std::string& encoding, const std::uint8_t* payload,
                                         std::size_t size, std::uint64_t entries,
                                         const TableContext& ctx) {
    if (encoding == "hash14") return std::make_unique<Hash14Table>(payload, size, entries);
    if (encoding == "dense") return std::make_unique<DenseTable>(payload, size, entries, ctx);
    if (encoding == "candidates") return std::make_unique<CandidatesTable>(payload, size, entries, ctx);
    throw std::runtime_error("unknown table encoding '" + encoding + "'");
}

}  // namespace lat
