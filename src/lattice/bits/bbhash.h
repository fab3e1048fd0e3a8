#pragma once
// A minimal perfect hash function by BBHash (Limasset, Rizk, Chikhi, Peterlongo, "Fast and
// scalable minimal perfect hashing for massive key sets", SEA 2017).
//
// Level l is a bit array of about gamma x (keys still unplaced) bits; every unplaced key hashes
// to one bit of it. Keys alone on their bit are placed there (the bit is set); the others fall
// to the next level. The levels are concatenated into one bit vector, so a key's value is the
// rank of its bit: a bijection from the keys onto [0, N). A rank sample every 512 bits makes
// that one table read and at most eight popcounts.
//
// A key that is not in the set walks the levels like any other and is mapped to some value as
// soon as it lands on a set bit; only if it misses every level is it rejected (kNone).
//
// Serialised as 64-bit little-endian words:
//   n, levels L, words W, L + 1 level starts (in words), W bit words, W / 8 + 1 rank samples
//   (32 bits each, two per word).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace lat {

class BBHash {
public:
    static constexpr std::uint64_t kNone = ~std::uint64_t{0};
    static constexpr int kMaxLevels = 64;

    // Over distinct keys (fewer than 2^32); throws std::invalid_argument when they are not
    // distinct. Parallel; the result depends on the key set only (not on its order, nor on the
    // thread count).
    static std::vector<std::uint64_t> build(std::span<const std::uint64_t> keys,
                                            double gamma = 2.0);

    // Over words made by build (8-byte aligned; must outlive this). Throws std::runtime_error
    // when they are inconsistent: after that, every value returned is below keys().
    BBHash(const std::uint8_t* data, std::size_t size);

    // The key's value in [0, keys()), or kNone when it falls through every level.
    std::uint64_t operator()(std::uint64_t key) const;
    // Starts loading what the first level needs for the key (to overlap the cache misses of
    // a run of lookups).
    void prefetch(std::uint64_t key) const;

    std::uint64_t keys() const { return n_; }
    int levels() const { return levels_; }
    std::size_t bytes() const { return size_; }
    // Bits of the bit vector set at each level, and its size in bits.
    std::uint64_t level_bits(int l) const { return (start_[l + 1] - start_[l]) * 64; }
    // The share of keys outside the set that are mapped to some value, not rejected (a random
    // key lands on a set bit of some level): 1 - prod_l (1 - ones_l / bits_l).
    double accept_rate() const;

    // The hash of a key that its level hashes are derived from (also usable for fingerprints:
    // its low bits are independent of where the key lands).
    static std::uint64_t key_hash(std::uint64_t key);

private:
    const std::uint64_t* start_ = nullptr;  // L + 1 level starts, in words
    const std::uint64_t* bits_ = nullptr;
    const std::uint32_t* rank_ = nullptr;
    std::uint64_t n_ = 0, words_ = 0;
    int levels_ = 0;
    std::size_t size_ = 0;
};

}  // namespace lat
