#pragma once
// Bit-level storage for compact tables: fixed-width fields packed into 64-bit words, and a
// bit vector with a rank directory (count of set bits before a position in O(1)).
#include <bit>
#include <cassert>
#include <cstdint>
#include <vector>

namespace lat {

// Bits [pos, pos + width) of a word array, width <= 64; reads the next word only when the
// field straddles it, and no word at all for width 0.
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

// Appends fixed-width fields to a growing word array.
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

inline void write_bits(std::uint64_t* w, std::uint64_t offset, unsigned bits, std::uint64_t value) {
    assert(bits == 64 || value < (std::uint64_t{1} << bits));
    const std::uint64_t i = offset >> 6;
    const unsigned s = offset & 63;
    const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    w[i] = (w[i] & ~(mask << s)) | (value << s);
    if (s + bits > 64) {
        const unsigned lo = 64 - s;
        w[i + 1] = (w[i + 1] & ~(mask >> lo)) | (value >> lo);
    }
}

// Rank over a bit vector: one 32-bit count per 512 bits (6.25 % on top of the bits).
class RankIndex {
public:
    static constexpr int kBlockWords = 8;

    // counts.size() must be words / 8 + 1.
    static void build(const std::uint64_t* words, std::uint64_t nwords, std::uint32_t* counts) {
        std::uint64_t total = 0;
        for (std::uint64_t i = 0; i < nwords; ++i) {
            if (i % kBlockWords == 0) counts[i / kBlockWords] = static_cast<std::uint32_t>(total);
            total += static_cast<std::uint64_t>(std::popcount(words[i]));
        }
        counts[(nwords + kBlockWords - 1) / kBlockWords] = static_cast<std::uint32_t>(total);
    }
    static std::uint64_t count_entries(std::uint64_t nwords) {
        return (nwords + kBlockWords - 1) / kBlockWords + 1;
    }
    // Whether counts is exactly the directory build() makes for these words: what a table read
    // from a file checks before any rank() can index with a count.
    static bool valid(const std::uint64_t* words, std::uint64_t nwords, const std::uint32_t* counts) {
        std::uint64_t total = 0;
        for (std::uint64_t i = 0; i < nwords; ++i) {
            if (i % kBlockWords == 0 && counts[i / kBlockWords] != total) return false;
            total += static_cast<std::uint64_t>(std::popcount(words[i]));
        }
        return counts[(nwords + kBlockWords - 1) / kBlockWords] == total;
    }

    RankIndex() = default;
    RankIndex(const std::uint64_t* words, const std::uint32_t* counts) : w_(words), c_(counts) {}

    bool test(std::uint64_t i) const { return (w_[i >> 6] >> (i & 63)) & 1; }
    // Set bits before position i.
    std::uint64_t rank(std::uint64_t i) const {
        const std::uint64_t word = i >> 6;
        std::uint64_t r = c_[word / kBlockWords];
        for (std::uint64_t k = word / kBlockWords * kBlockWords; k < word; ++k)
            r += static_cast<std::uint64_t>(std::popcount(w_[k]));
        const std::uint64_t below = (i & 63) ? w_[word] << (64 - (i & 63)) : 0;
        return r + static_cast<std::uint64_t>(std::popcount(below));
    }

private:
    const std::uint64_t* w_ = nullptr;
    const std::uint32_t* c_ = nullptr;
};

}  // namespace lat
