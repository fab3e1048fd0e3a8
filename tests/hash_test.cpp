// HashStream gives hash_bytes' value however the bytes are split, and hash_bytes is the
// function table files were checksummed with (a copy of its first form here).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "util/hash.h"

namespace lat {
namespace {

std::uint64_t first_form(const void* data, std::size_t n, std::uint64_t seed) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::uint64_t h[4] = {seed ^ 0x9E3779B97F4A7C15ull, seed + 0x632BE59BD9B4E019ull, ~seed,
                          seed * 0xD6E8FEB86659FD93ull + 1};
    std::size_t i = 0;
    for (; i + 32 <= n; i += 32)
        for (int k = 0; k < 4; ++k) {
            std::uint64_t w;
            std::memcpy(&w, p + i + 8 * k, 8);
            h[k] = (h[k] ^ w) * 0x9FB21C651E98DF25ull;
            h[k] ^= h[k] >> 29;
        }
    std::uint64_t acc = n;
    for (; i + 8 <= n; i += 8) {
        std::uint64_t w;
        std::memcpy(&w, p + i, 8);
        acc = mix64(acc ^ w);
    }
    std::uint64_t tail = 0;
    if (i < n) std::memcpy(&tail, p + i, n - i);
    acc = mix64(acc ^ tail);
    for (const std::uint64_t v : h) acc = mix64(acc ^ v);
    return acc;
}

TEST(HashStream, AnySplitGivesTheWholeHash) {
    std::mt19937_64 rng(5);
    std::vector<unsigned char> bytes(5000);
    for (unsigned char& b : bytes) b = static_cast<unsigned char>(rng());
    for (const std::size_t n : {0, 1, 7, 8, 31, 32, 33, 64, 100, 1000, 5000})
        for (const std::uint64_t seed : {0ull, 12345ull}) {
            const std::uint64_t whole = first_form(bytes.data(), n, seed);
            EXPECT_EQ(hash_bytes(bytes.data(), n, seed), whole) << n;
            for (int trial = 0; trial < 20; ++trial) {
                HashStream h(seed);
                for (std::size_t done = 0; done < n;) {
                    const std::size_t piece = std::min<std::size_t>(n - done, rng() % 70);
                    h.add(bytes.data() + done, piece);
                    done += piece;
                }
                ASSERT_EQ(h.value(), whole) << "n " << n << ", trial " << trial;
            }
        }
    EXPECT_EQ(hash_bytes(nullptr, 0), first_form(nullptr, 0, 0));
}

}  // namespace
}  // namespace lat
