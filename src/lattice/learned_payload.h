#pragma once
// The learned encoding's payload, in little-endian 64-bit words (see docs/encoding-learned.md):
//   header     6 words: magic and version; cells; step; field widths; exception counts
//   model      the coarse samples, (model_t + 2 model_n) bits each, in LearnedLayout order
//   misses     Elias-Fano set of "miss" exception keys (high words, then low words)
//   hits       Elias-Fano set of "hit" exception keys
//   values     per hit exception, t (ex_t bits) and the normal (2 ex_n bits), in key order
// Section sizes follow from the header, so they are checked against the payload size.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "lattice/learned_table.h"
#include "lattice/octahedral.h"

namespace lat::learned {

inline constexpr std::uint32_t kMagic = 0x444E524C;  // "LRND"
inline constexpr std::uint32_t kVersion = 1;
inline constexpr std::size_t kHeaderWords = 6;

struct Header {
    std::array<int, 3> cells{};
    int step = 0;
    LearnedWidths widths;
    std::uint64_t misses = 0, hits = 0;
};

inline std::uint64_t sample_width(const LearnedWidths& w) { return w.model_t + 2 * w.model_n; }
inline std::uint64_t value_width(const LearnedWidths& w) { return w.ex_t + 2 * w.ex_n; }

// A sample's code: t in model_t bits (all ones: a miss), then the normal's u and v.
inline std::uint64_t encode_sample(bool hit, double t, Vec3 n, const LearnedWidths& w) {
    const std::uint64_t miss = (std::uint64_t{1} << w.model_t) - 1;
    if (!hit) return miss;
    const auto tc = static_cast<std::uint64_t>(std::lround(std::clamp(t, 0.0, 1.0) * double(miss - 1)));
    const Oct o = oct_encode_precise(n, static_cast<int>(w.model_n));
    return tc | (std::uint64_t{o.u} << w.model_t) | (std::uint64_t{o.v} << (w.model_t + w.model_n));
}

inline LearnedSample decode_sample(std::uint64_t code, const LearnedWidths& w) {
    const std::uint64_t miss = (std::uint64_t{1} << w.model_t) - 1;
    const std::uint64_t nmask = (std::uint64_t{1} << w.model_n) - 1;
    LearnedSample s;
    const std::uint64_t tc = code & miss;
    if (tc == miss) return s;
    s.hit = true;
    s.t = double(tc) / double(miss - 1);
    const auto u = static_cast<std::uint32_t>((code >> w.model_t) & nmask);
    const auto v = static_cast<std::uint32_t>((code >> (w.model_t + w.model_n)) & nmask);
    s.n = oct_decode({u, v}, static_cast<int>(w.model_n));
    return s;
}

// A hit exception's value: t in ex_t bits, then the normal's u and v.
inline double decode_value_t(std::uint64_t code, const LearnedWidths& w) {
    const std::uint64_t top = (std::uint64_t{1} << w.ex_t) - 1;
    return double(code & top) / double(top);
}
inline std::uint64_t encode_value_t(double t, unsigned bits) {
    const std::uint64_t top = (std::uint64_t{1} << bits) - 1;
    return static_cast<std::uint64_t>(std::lround(std::clamp(t, 0.0, 1.0) * double(top)));
}
inline Vec3 decode_value_n(std::uint64_t code, const LearnedWidths& w) {
    const std::uint64_t nmask = (std::uint64_t{1} << w.ex_n) - 1;
    const auto u = static_cast<std::uint32_t>((code >> w.ex_t) & nmask);
    const auto v = static_cast<std::uint32_t>((code >> (w.ex_t + w.ex_n)) & nmask);
    return oct_decode({u, v}, static_cast<int>(w.ex_n));
}

}  // namespace lat::learned
