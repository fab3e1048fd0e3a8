#include "lattice/encodings.h"

#include <stdexcept>

#include "lattice/hash14_table.h"
#include "lattice/learned_table.h"
#include "util/error.h"

namespace lat {

const std::vector<EncodingInfo>& table_encodings() {
    static const std::vector<EncodingInfo> list = {
        {"hash14", "the paper's hash table, 14-byte entries with key and overflow chain",
         Hash14Table::kMaxPoints, 15.0, true},
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
    if (encoding == "learned") return LearnedTable::build(r.raw, ctx, opt);
    throw std::invalid_argument("encode_table: unknown encoding " + encoding);
}

std::unique_ptr<LatticeTable> open_table(const std::string& encoding, const std::uint8_t* payload,
                                         std::size_t size, std::uint64_t entries,
                                         const TableContext& ctx) {
    if (encoding == "hash14") return std::make_unique<Hash14Table>(payload, size, entries);
    if (encoding == "learned") return std::make_unique<LearnedTable>(payload, size, entries, ctx);
    throw std::runtime_error("unknown table encoding '" + encoding + "'");
}

}  // namespace lat
