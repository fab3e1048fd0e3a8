#include "lattice/bits/bbhash.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "util/hash.h"

namespace lat {
namespace {

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;
constexpr std::size_t kBlock = std::size_t{1} << 16;  // keys per task when filtering
constexpr std::uint64_t kRankWords = 8;               // a rank sample every 512 bits

// The key's bit in a level of `bits` bits (multiply-shift range reduction, Lemire).
std::uint64_t position(std::uint64_t hk, int level, std::uint64_t bits) {
    const std::uint64_t h = mix64(hk ^ (kGolden * static_cast<std::uint64_t>(level + 1)));
    __extension__ using u128 = unsigned __int128;  // -Wpedantic: a GCC extension
    return static_cast<std::uint64_t>((static_cast<u128>(h) * bits) >> 64);
}

bool test_bit(const std::uint64_t* w, std::uint64_t i) {
    return (w[i >> 6] >> (i & 63)) & 1;
}

std::uint64_t rank_words(std::uint64_t words) {
    return (words / kRankWords + 2) / 2;
}

}  // namespace

std::uint64_t BBHash::key_hash(std::uint64_t key) {
    return mix64(key + kGolden);
}

std::vector<std::uint64_t> BBHash::build(std::span<const std::uint64_t> keys, double gamma) {
    if (keys.size() >= (std::uint64_t{1} << 32))
        throw std::length_error("bbhash: 2^32 keys or more");
    gamma = std::max(gamma, 0.5);
    std::vector<std::uint64_t> bits, starts{0};
    // The unplaced keys' hashes; the input is read once, then only what falls through is kept.
    std::vector<std::uint64_t> cur(keys.size()), next;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), kBlock), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) cur[i] = key_hash(keys[i]);
    });
    int level = 0;
    for (; !cur.empty(); ++level) {
        if (level == kMaxLevels) throw std::invalid_argument("bbhash: keys are not distinct");
        const auto want = static_cast<std::uint64_t>(std::ceil(gamma * double(cur.size())));
        const std::uint64_t words = std::max<std::uint64_t>(1, (want + 63) / 64),
                            nbits = words * 64;
        // Bits hit at least once, and at least twice: the same whatever the order of the hits.
        std::vector<std::uint64_t> seen(words, 0), twice(words, 0);
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, cur.size(), kBlock), [&](const auto& r) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                    const std::uint64_t p = position(cur[i], level, nbits),
                                        m = std::uint64_t{1} << (p & 63);
                    const std::uint64_t old =
                        std::atomic_ref(seen[p >> 6]).fetch_or(m, std::memory_order_relaxed);
                    if (old & m)
                        std::atomic_ref(twice[p >> 6]).fetch_or(m, std::memory_order_relaxed);
                }
            });
        for (std::uint64_t w = 0; w < words; ++w) bits.push_back(seen[w] & ~twice[w]);
        starts.push_back(bits.size());
        // The keys that collided, in their order (blocks counted, then written in place).
        const std::size_t blocks = (cur.size() + kBlock - 1) / kBlock;
        std::vector<std::size_t> at(blocks + 1, 0);
        auto collided = [&](std::uint64_t hk) {
            return test_bit(twice.data(), position(hk, level, nbits));
        };
        tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
            const std::size_t end = std::min(cur.size(), (b + 1) * kBlock);
            for (std::size_t i = b * kBlock; i < end; ++i) at[b + 1] += collided(cur[i]);
        });
        for (std::size_t b = 0; b < blocks; ++b) at[b + 1] += at[b];
        next.resize(at[blocks]);
        tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
            const std::size_t end = std::min(cur.size(), (b + 1) * kBlock);
            std::size_t o = at[b];
            for (std::size_t i = b * kBlock; i < end; ++i)
                if (collided(cur[i])) next[o++] = cur[i];
        });
        cur.swap(next);
    }

    const std::uint64_t words = bits.size(), samples = words / kRankWords + 1;
    std::vector<std::uint64_t> out;
    out.reserve(3 + starts.size() + words + rank_words(words));
    out.insert(out.end(), {keys.size(), static_cast<std::uint64_t>(level), words});
    out.insert(out.end(), starts.begin(), starts.end());
    out.insert(out.end(), bits.begin(), bits.end());
    std::vector<std::uint32_t> rank(rank_words(words) * 2, 0);
    std::uint64_t ones = 0;
    for (std::uint64_t s = 0; s < samples; ++s) {
        rank[s] = static_cast<std::uint32_t>(ones);
        for (std::uint64_t w = s * kRankWords; w < std::min(words, (s + 1) * kRankWords); ++w)
            ones += std::popcount(bits[w]);
    }
    const std::size_t at = out.size();
    out.resize(at + rank.size() / 2);
    std::memcpy(out.data() + at, rank.data(), rank.size() * 4);
    return out;
}

BBHash::BBHash(const std::uint8_t* data, std::size_t size) : size_(size) {
    if (reinterpret_cast<std::uintptr_t>(data) % 8 != 0)
        throw std::runtime_error("bbhash: misaligned data");
    if (size < 24 || size % 8 != 0) throw std::runtime_error("bbhash: bad size");
    const auto* w = reinterpret_cast<const std::uint64_t*>(data);
    const std::uint64_t total = size / 8;
    n_ = w[0];
    words_ = w[2];
    if (n_ >= (std::uint64_t{1} << 32) || w[1] > kMaxLevels || words_ > total)
        throw std::runtime_error("bbhash: bad counts");
    levels_ = static_cast<int>(w[1]);
    if (3 + (levels_ + 1) + words_ + rank_words(words_) != total)
        throw std::runtime_error("bbhash: inconsistent size");
    start_ = w + 3;
    bits_ = start_ + levels_ + 1;
    rank_ = reinterpret_cast<const std::uint32_t*>(bits_ + words_);
    if (start_[0] != 0 || start_[levels_] != words_)
        throw std::runtime_error("bbhash: bad level starts");
    for (int l = 0; l < levels_; ++l)
        if (start_[l + 1] <= start_[l]) throw std::runtime_error("bbhash: bad level starts");
    // Checking every rank sample (a few milliseconds for 20 M keys) bounds every value by n.
    std::uint64_t ones = 0;
    for (std::uint64_t s = 0; s <= words_ / kRankWords; ++s) {
        if (rank_[s] != ones) throw std::runtime_error("bbhash: bad rank samples");
        for (std::uint64_t i = s * kRankWords; i < std::min(words_, (s + 1) * kRankWords); ++i)
            ones += std::popcount(bits_[i]);
    }
    if (ones != n_) throw std::runtime_error("bbhash: bit count does not match the keys");
}

std::uint64_t BBHash::operator()(std::uint64_t key) const {
    const std::uint64_t hk = key_hash(key);
    for (int l = 0; l < levels_; ++l) {
        const std::uint64_t p = start_[l] * 64 + position(hk, l, (start_[l + 1] - start_[l]) * 64);
        if (!test_bit(bits_, p)) continue;
        const std::uint64_t word = p >> 6, s = word / kRankWords;
        std::uint64_t r = rank_[s];
        for (std::uint64_t i = s * kRankWords; i < word; ++i) r += std::popcount(bits_[i]);
        return r + std::popcount(bits_[word] & ((std::uint64_t{1} << (p & 63)) - 1));
    }
    return kNone;
}

void BBHash::prefetch(std::uint64_t key) const {
    if (levels_ == 0) return;
    const std::uint64_t p = position(key_hash(key), 0, start_[1] * 64);
    __builtin_prefetch(bits_ + (p >> 6));
    __builtin_prefetch(rank_ + (p >> 6) / kRankWords);
}

double BBHash::accept_rate() const {
    double reject = 1;
    for (int l = 0; l < levels_; ++l) {
        std::uint64_t ones = 0;
        for (std::uint64_t i = start_[l]; i < start_[l + 1]; ++i) ones += std::popcount(bits_[i]);
        reject *= 1 - double(ones) / double(level_bits(l));
    }
    return 1 - reject;
}

}  // namespace lat
