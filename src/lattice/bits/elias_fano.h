#pragma once
// Elias-Fano sets (used by the learned encoding): sorted key sets at about
// 2 + log2(universe / n) bits per key whose membership query also returns the key's rank (the
// index of its values).
#include <cstdint>
#include <span>
#include <vector>

#include "lattice/bits/bit_array.h"

namespace lat {

// Elias-Fano: key k splits into high = k >> low_bits, stored in unary in `high` (bit high + i
// set for the i-th key), and its low bits, packed. Buckets of equal high part are delimited by
// zeros; a sampled select over the zeros finds a bucket in a few words.
struct EliasFanoShape {
    std::uint64_t n = 0;         // keys
    std::uint64_t universe = 0;  // keys are < universe
    unsigned low_bits = 0;
    std::uint64_t buckets() const { return (universe >> low_bits) + 1; }
    std::uint64_t high_bits() const { return n + buckets(); }
    std::uint64_t high_words() const { return words_for_bits(high_bits()); }
    std::uint64_t low_words() const { return words_for_bits(n * low_bits); }
    static EliasFanoShape for_keys(std::uint64_t n, std::uint64_t universe);
};

// Encodes sorted distinct keys < universe: the high words, then the low words.
std::vector<std::uint64_t> elias_fano_encode(std::span<const std::uint64_t> keys,
                                             const EliasFanoShape& shape);

class EliasFanoView {
public:
    static constexpr unsigned kSampleLog = 6;  // a select sample every 64 zeros

    EliasFanoView() = default;
    // Over `shape.high_words() + shape.low_words()` words; throws std::runtime_error when the
    // high part does not hold exactly n ones and buckets() zeros (so queries stay in range), or
    // is longer than 2^32 bits.
    EliasFanoView(const std::uint64_t* words, const EliasFanoShape& shape);

    // Whether `key` is in the set, and if so its rank.
    bool find(std::uint64_t key, std::uint64_t& rank) const;
    std::uint64_t size() const { return shape_.n; }
    // Bytes of the select samples built at open (not part of the payload).
    std::uint64_t index_bytes() const { return samples_.size() * sizeof(std::uint32_t); }

private:
    const std::uint64_t* high_ = nullptr;
    const std::uint64_t* low_ = nullptr;
    EliasFanoShape shape_;
    std::vector<std::uint32_t> samples_;  // position of every 2^kSampleLog-th zero

    std::uint64_t select_zero(std::uint64_t j) const;
};

}  // namespace lat
