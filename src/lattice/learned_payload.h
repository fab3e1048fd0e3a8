#pragma once
// The learned encoding's payload, in little-endian 64-bit words (docs/encoding-learned.md):
//   header      11 words: magic and version; cells; field and exception value widths; node
//               spacing g; nodes per axis; dmax; dense bricks; the four exception counts
//   field       dense-brick bitmap, sign bitmap (one bit per brick each), the dense bricks'
//               nodes (125 per brick, dist_bits + 2 normal_bits each)
//   exceptions  per kind (miss, hit, normal, t): an Elias-Fano set of pair keys (high words,
//               then low words)
//   values      per kind with values, in key order: hit t (ex_t bits) and normal u, v (ex_n
//               bits each); normal u, v; t
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
inline constexpr std::uint32_t kVersion = 3;
inline constexpr std::size_t kHeaderWords = 11;

// What an exception corrects: the model hits a pair that misses (kMiss); the model misses or
// both t and the normal are out of bounds (kHit: both stored); only the normal is (kNormal);
// only t is (kT).
enum ExceptionKind { kMiss = 0, kHit = 1, kNormal = 2, kT = 3, kKinds = 4 };

struct Header {
    std::array<int, 3> cells{};
    FieldShape field;
    unsigned ex_t = 0, ex_n = 0;
    std::uint64_t dense = 0;
    std::array<std::uint64_t, kKinds> count{};
};

// Bits of one exception's values.
inline std::uint64_t value_width(const Header& h, int kind) {
    return kind == kHit      ? h.ex_t + 2 * h.ex_n
           : kind == kNormal ? 2 * h.ex_n
           : kind == kT      ? h.ex_t
                             : 0;
}

inline std::array<std::uint64_t, kHeaderWords> encode_header(const Header& h) {
    auto bits = [](double x) {
        std::uint64_t w;
        std::memcpy(&w, &x, 8);
        return w;
    };
    const FieldShape& f = h.field;
    const std::uint64_t widths =
        f.dist_bits | (f.normal_bits << 8) | (h.ex_t << 16) | (std::uint64_t{h.ex_n} << 24);
    return {
        kMagic | (std::uint64_t{kVersion} << 32),
        std::uint64_t(std::uint32_t(h.cells[0])) | (std::uint64_t(std::uint32_t(h.cells[1])) << 32),
        std::uint64_t(std::uint32_t(h.cells[2])) | (widths << 32),
        bits(f.g),
        std::uint64_t(f.nodes[0]) | (std::uint64_t(f.nodes[1]) << 21) |
            (std::uint64_t(f.nodes[2]) << 42),
        bits(f.dmax),
        h.dense,
        h.count[0],
        h.count[1],
        h.count[2],
        h.count[3]};
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
    for (int k = 0; k < kKinds; ++k) h.count[std::size_t(k)] = w[7 + k];
    return h;
}

// Section sizes in words, for a header whose counts are already bounded (no overflow).
struct Sections {
    std::uint64_t bitmap = 0, nodes = 0;  // each of the two bitmaps; the dense nodes
    std::array<EliasFanoShape, kKinds> keys;
    std::array<std::uint64_t, kKinds> values{};
    std::uint64_t total() const {
        std::uint64_t n = kHeaderWords + 2 * bitmap + nodes;
        for (int k = 0; k < kKinds; ++k)
            n += keys[std::size_t(k)].high_words() + keys[std::size_t(k)].low_words() +
                 values[std::size_t(k)];
        return n;
    }
};
inline Sections sections(const Header& h, std::uint64_t universe) {
    Sections s;
    s.bitmap = words_for_bits(h.field.brick_count());
    s.nodes = words_for_bits(h.dense * h.field.brick_bits());
    for (int k = 0; k < kKinds; ++k) {
        s.keys[std::size_t(k)] = EliasFanoShape::for_keys(h.count[std::size_t(k)], universe);
        s.values[std::size_t(k)] = words_for_bits(h.count[std::size_t(k)] * value_width(h, k));
    }
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
