#pragma once
// Bit-level storage for compact tables: fixed-width fields packed into 64-bit words, and a
// bit vector with a rank directory (count of set bits before a position in O(1)).
#include <bit>
#include <cassert>
#include <cstdint>
#include <vector>

namespace lat {

// Fields of up to 57 bits at any bit offset of a word array (which needs one word of slack).
inline std::uint64_t read_bits(const std::uint64_t* w, std::uint64_t offset, int bits) {
    const std::uint64_t i = offset >> 6;
    const unsigned s = offset & 63;
    std::uint64_t v = w[i] >> s;
    if (s + static_cast<unsigned>(bits) > 64) v |= w[i + 1] << (64 - s);
    return bits == 64 ? v : v & ((std::uint64_t{1} << bits) - 1);
}

inline void write_bits(std::uint64_t* w, std::uint64_t offset, int bits, std::uint64_t value) {
    assert(bits == 64 || value < (std::uint64_t{1} << bits));
    const std::uint64_t i = offset >> 6;
    const unsigned s = offset & 63;
    const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    w[i] = (w[i] & ~(mask << s)) | (value << s);
    if (s + static_cast<unsigned>(bits) > 64) {
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
