#pragma once
// The learned encoding's payload, in little-endian 64-bit words (docs/encoding-learned.md):
//   header      9 words: magic and version; cells; field and exception value widths; node
//               spacing g; nodes per axis; dmax; dense bricks; hits and corrections
//   field       dense-brick bitmap, sign bitmap (one bit per brick each), the dense bricks'
//               nodes (125 per brick, dist_bits + 2 normal_bits each)
//   hits        Elias-Fano set of the keys of "hit" exceptions (high words, then low words)
//   corrections Elias-Fano set of the keys of the other exceptions
//   values      per hit, in key order: t (ex_t bits), normal u, v (ex_n bits each); per
//               correction: its kind (2 bits) and its value in a slot of max(ex_t, 2 ex_n) bits
// Every section's size follows from the header and is checked against the payload's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "lattice/bits/elias_fano.h"
#include "lattice/encodings/learned/learned_field.h"

namespace lat::learned {

inline constexpr std::uint32_t kMagic = 0x444E524C;  // "LRND"
inline constexpr std::uint32_t kVersion = 4;
inline constexpr std::size_t kHeaderWords = 9;

// What an exception corrects: the model misses, or errs in both t and the normal (kHit: both
// stored); the model hits a pair that misses (kMiss); it errs in the normal alone (kNormal) or
// in t alone (kT). The last three are "corrections" of a predicted hit, in one set so that a
// lookup searches it once.
enum ExceptionKind { kMiss = 0, kHit = 1, kNormal = 2, kT = 3, kKinds = 4 };

struct Header {
    std::array<int, 3> cells{};
    FieldShape field;
    unsigned ex_t = 0, ex_n = 0;
    std::uint64_t dense = 0, hits = 0, corrections = 0;
};

inline unsigned hit_width(const Header& h) {
    return h.ex_t + 2 * h.ex_n;
}
inline unsigned record_width(const Header& h) {
    return 2 + std::max(h.ex_t, 2 * h.ex_n);
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
        h.hits,
        h.corrections};
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
    h.hits = w[7];
    h.corrections = w[8];
    return h;
}

// Section sizes in words, for a header whose counts are already bounded (no overflow).
struct Sections {
    std::uint64_t bitmap = 0, nodes = 0;  // each of the two bitmaps; the dense nodes
    EliasFanoShape hits, corrections;
    std::uint64_t hit_values = 0, records = 0;
    std::uint64_t total() const {
        return kHeaderWords + 2 * bitmap + nodes + hits.high_words() + hits.low_words() +
               corrections.high_words() + corrections.low_words() + hit_values + records;
    }
};
inline Sections sections(const Header& h, std::uint64_t universe) {
    Sections s;
    s.bitmap = words_for_bits(h.field.brick_count());
    s.nodes = words_for_bits(h.dense * h.field.brick_bits());
    s.hits = EliasFanoShape::for_keys(h.hits, universe);
    s.corrections = EliasFanoShape::for_keys(h.corrections, universe);
    s.hit_values = words_for_bits(h.hits * hit_width(h));
    s.records = words_for_bits(h.corrections * record_width(h));
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
