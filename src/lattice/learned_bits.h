#pragma once
// Bit-packed arrays and Elias-Fano sets for the learned encoding (learned_table.h): fixed-width
// fields in little-endian 64-bit words, and sorted key sets at about 2 + log2(universe / n) bits
// per key whose membership query also returns the key's rank (the index of its values).
#include <cstdint>
#include <span>
#include <vector>

namespace lat {

// Bits [pos, pos + width) of a word array, width <= 64; reads the next word only when the
// field straddles it.
inline std::uint64_t read_bits(const std::uint64_t* w, std::uint64_t pos, unsigned width) {
    if (width == 0) return 0;
    const std::uint64_t i = pos >> 6;
    const unsigned sh = static_cast<unsigned>(pos & 63);
    std::uint64_t v = w[i] >> sh;
    if (sh + width > 64) v |= w[i + 1] << (64 - sh);
    return width == 64 ? v : v & ((std::uint64_t{1} << width) - 1);
}

inline std::uint64_t words_for_bits(std::uint64_t bits) {
    return (bits + 63) / 64;
}

class BitWriter {
public:
    explicit BitWriter(std::uint64_t reserve_bits = 0) {
        words_.reserve(words_for_bits(reserve_bits));
    }
    void put(std::uint64_t v, unsigned width) {
        if (width == 0) return;
        if (width < 64) v &= (std::uint64_t{1} << width) - 1;
        const unsigned sh = static_cast<unsigned>(bits_ & 63);
        if (sh == 0) words_.push_back(0);
        words_.back() |= v << sh;
        if (sh + width > 64) words_.push_back(v >> (64 - sh));
        bits_ += width;
    }
    std::uint64_t bits() const { return bits_; }
    const std::vector<std::uint64_t>& words() const { return words_; }

private:
    std::vector<std::uint64_t> words_;
    std::uint64_t bits_ = 0;
};

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
