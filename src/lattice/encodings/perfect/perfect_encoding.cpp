#include "lattice/encoding.h"
#include "lattice/encodings/perfect/perfect_table.h"

namespace lat {

namespace {

// One descriptor per fingerprint width; building holds the keys (8 bytes a hit) and those that
// collide at the first level.
template <int kFingerprintBits>
constexpr Encoding perfect_encoding(std::string_view name, std::string_view summary) {
    return {
        .name = name,
        .summary = summary,
        .max_points = PerfectTable::kMaxPoints,
        .bytes_per_hit = 17.0 + kFingerprintBits / 8,
        .build = [](const RawHits& hits, const TableContext&, const EncodeOptions&) {
            return PerfectTable::build(hits, kFingerprintBits);
        },
        .open = [](const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                   const TableContext&) -> std::unique_ptr<LatticeTable> {
            return std::make_unique<PerfectTable>(payload, size, entries, kFingerprintBits);
        },
        // A perfect hash answers a missing key with some stored hit, anywhere in the box.
        .error_bound = [](const TableContext&, const EncodeOptions&) { return kInfinity; },
    };
}

}  // namespace

extern const Encoding kPerfect5Encoding, kPerfect6Encoding, kPerfect7Encoding;
// Experimental: the paper's proposal measured, not meant for images (perfect5's misses come
// back as hits; its fingerprinted variants measure the fix).
const Encoding kPerfect5Encoding = perfect_encoding<0>(
    "perfect5",
    "experimental, section 5.2.1: minimal perfect hash (BBHash), 5-byte entries, no keys");
const Encoding kPerfect6Encoding = perfect_encoding<8>(
    "perfect6", "experimental: perfect5 with an 8-bit key fingerprint per entry (6 bytes)");
const Encoding kPerfect7Encoding = perfect_encoding<16>(
    "perfect7", "experimental: perfect5 with a 16-bit key fingerprint per entry (7 bytes)");

}  // namespace lat
