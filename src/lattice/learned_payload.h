#pragma once
// The learned encoding's payload, in little-endian 64-bit words (docs/encoding-learned.md):
//   header   9 words: magic and version; cells; field widths and exception value widths;
//            node spacing g; nodes per axis; dmax; dense bricks; miss and hit exceptions
//   field    dense-brick bitmap, sign bitmap (one bit per brick each), the dense bricks'
//            nodes (125 per brick, dist_bits + 2 normal_bits each)
//   misses   Elias-Fano set of "miss" keys (high words, then low words)
//   hits     Elias-Fano set of "hit" keys
//   values   per hit exception in key order: t (ex_t bits), normal u and v (ex_n bits each)
// Every section's size follows from the header and is checked against the payload's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "lattice/learned_bits.h"
#include "lattice/learned_field.h"

namespace lat::learned {

inline constexpr std::uint32_t kMagic = 0x444E524C;  // "LRND"
inline constexpr std::uint32_t kVersion = 2;
inline constexpr std::size_t kHeaderWords = 9;

struct Header {
    std::array<int, 3> cells{};
    FieldShape field;
    unsigned ex_t = 0, ex_n = 0;
    std::uint64_t dense = 0, misses = 0, hits = 0;
};

inline std::array<std::uint64_t, kHeaderWords> encode_header(const Header& h) {
    auto bits = [](double x) {
        std::uint64_t w;
        std::memcpy(&w, &x, 8);
        return w;
    };
    const FieldShape& f = h.field;
    const std::uint64_t widths =
        f.dist_bits | (f.normal_bits << 8) | (h.ex_t << 16) | (h.ex_n << 24);
    return {
        kMagic | (std::uint64_t{kVersion} << 32),
        std::uint64_t(std::uint32_t(h.cells[0])) | (std::uint64_t(std::uint32_t(h.cells[1])) << 32),
        std::uint64_t(std::uint32_t(h.cells[2])) | (widths << 32),
        bits(f.g),
        std::uint64_t(f.nodes[0]) | (std::uint64_t(f.nodes[1]) << 21) |
            (std::uint64_t(f.nodes[2]) << 42),
        bits(f.dmax),
        h.dense,
        h.misses,
        h.hits};
}

// The fields as stored; the caller validates them.
inline Header decode_header(const std::uint64_t* w) {
    auto real = [](std::uint64_t x) {
        double d;
        std::memcpy(&d, &x, 8);
        return d;
    };
    Header h;
    h.cells = {int(std::uint32_t(w[1])), int(std::uint32_t(w[1] >> 32)), int(std::uint32_t(w[2]))};
    const std::uint64_t widths = w[2] >> 32;
    h.field.dist_bits = widths & 0xFF;
    h.field.normal_bits = (widths >> 8) & 0xFF;
    h.ex_t = (widths >> 16) & 0xFF;
    h.ex_n = (widths >> 24) & 0xFF;
    h.field.g = real(w[3]);
    h.field.nodes = {int(w[4] & 0x1FFFFF), int((w[4] >> 21) & 0x1FFFFF),
                     int((w[4] >> 42) & 0x1FFFFF)};
    h.field.dmax = real(w[5]);
    h.dense = w[6];
    h.misses = w[7];
    h.hits = w[8];
    return h;
}

inline std::uint64_t value_width(unsigned ex_t, unsigned ex_n) {
    return ex_t + 2 * ex_n;
}

// Section sizes in words, for a header whose counts are already bounded (no overflow).
struct Sections {
    std::uint64_t bitmap = 0, nodes = 0;  // each of the two bitmaps; the dense nodes
    EliasFanoShape misses, hits;
    std::uint64_t values = 0;
    std::uint64_t total() const {
        return kHeaderWords + 2 * bitmap + nodes + misses.high_words() + misses.low_words() +
               hits.high_words() + hits.low_words() + values;
    }
};
inline Sections sections(const Header& h, std::uint64_t universe) {
    Sections s;
    s.bitmap = words_for_bits(h.field.brick_count());
    s.nodes = words_for_bits(h.dense * h.field.brick_bits());
    s.misses = EliasFanoShape::for_keys(h.misses, universe);
    s.hits = EliasFanoShape::for_keys(h.hits, universe);
    s.values = words_for_bits(h.hits * value_width(h.ex_t, h.ex_n));
    return s;
}

inline std::uint64_t encode_value_t(double t, unsigned bits) {
    const std::uint64_t top = (std::uint64_t{1} << bits) - 1;
    return static_cast<std::uint64_t>(std::lround(std::clamp(t, 0.0, 1.0) * double(top)));
}
inline double decode_value_t(std::uint64_t code, unsigned bits) {
    const std::uint64_t top = (std::uint64_t{1} << bits) - 1;
    return double(code & top) / double(top);
}

}  // namespace lat::learned
