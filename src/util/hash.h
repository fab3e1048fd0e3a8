#pragma once
// Fast non-cryptographic 64-bit hashing, for file checksums, fingerprints and hash tables.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace lat {

inline std::uint64_t mix64(std::uint64_t x) {  // splitmix64's finaliser
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

// Hash of a byte range; about 8 bytes per cycle, strong enough to detect corruption.
inline std::uint64_t hash_bytes(const void* data, std::size_t n, std::uint64_t seed = 0) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::uint64_t h[4] = {seed ^ 0x9E3779B97F4A7C15ull, seed + 0x632BE59BD9B4E019ull,
                          ~seed, seed * 0xD6E8FEB86659FD93ull + 1};
    std::size_t i = 0;
    for (; i + 32 <= n; i += 32) {
        for (int k = 0; k < 4; ++k) {
            std::uint64_t w;
            std::memcpy(&w, p + i + 8 * k, 8);
            h[k] = (h[k] ^ w) * 0x9FB21C651E98DF25ull;
            h[k] ^= h[k] >> 29;
        }
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

// Incremental fingerprint of typed values (doubles by bit pattern).
class Fingerprint {
public:
    Fingerprint& add(std::uint64_t v) {
        h_ = mix64(h_ ^ (v + 0x9E3779B97F4A7C15ull + (h_ << 6)));
        return *this;
    }
    Fingerprint& add(double v) {
        std::uint64_t b;
        std::memcpy(&b, &v, 8);
        return add(b);
    }
    Fingerprint& add(int v) { return add(static_cast<std::uint64_t>(static_cast<std::int64_t>(v))); }
    Fingerprint& add(std::string_view s) { return add(hash_bytes(s.data(), s.size(), s.size())); }
    std::uint64_t value() const { return h_; }

private:
    std::uint64_t h_ = 0x6C61747469636531ull;
};

}  // namespace lat
