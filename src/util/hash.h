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

// hash_bytes of bytes given in pieces, in order: the same value however they are split (a
// file's checksum taken as its pieces are written).
class HashStream {
public:
    explicit HashStream(std::uint64_t seed = 0)
        : h_{seed ^ 0x9E3779B97F4A7C15ull, seed + 0x632BE59BD9B4E019ull, ~seed,
             seed * 0xD6E8FEB86659FD93ull + 1} {}

    void add(const void* data, std::size_t n) {
        if (n == 0) return;
        const auto* p = static_cast<const unsigned char*>(data);
        n_ += n;
        if (fill_) {
            const std::size_t take = n < 32 - fill_ ? n : 32 - fill_;
            std::memcpy(buf_ + fill_, p, take);
            fill_ += take, p += take, n -= take;
            if (fill_ < 32) return;
            blocks(buf_, 1);
            fill_ = 0;
        }
        blocks(p, n / 32);
        p += n / 32 * 32, n %= 32;
        if (n) std::memcpy(buf_, p, n);
        fill_ = n;
    }

    std::uint64_t value() const {
        std::uint64_t acc = n_;
        std::size_t i = 0;
        for (; i + 8 <= fill_; i += 8) {
            std::uint64_t w;
            std::memcpy(&w, buf_ + i, 8);
            acc = mix64(acc ^ w);
        }
        std::uint64_t tail = 0;
        if (i < fill_) std::memcpy(&tail, buf_ + i, fill_ - i);
        acc = mix64(acc ^ tail);
        for (const std::uint64_t v : h_) acc = mix64(acc ^ v);
        return acc;
    }

private:
    std::uint64_t h_[4];
    std::uint64_t n_ = 0;
    unsigned char buf_[32] = {};  // the last bytes, short of a block of 32
    std::size_t fill_ = 0;

    // Four chains over blocks of 32 bytes, in a local copy of the state (the bytes read may
    // alias the members).
    void blocks(const unsigned char* p, std::size_t count) {
        std::uint64_t h[4] = {h_[0], h_[1], h_[2], h_[3]};
        for (std::size_t b = 0; b < count; ++b, p += 32)
            for (int k = 0; k < 4; ++k) {
                std::uint64_t w;
                std::memcpy(&w, p + 8 * k, 8);
                h[k] = (h[k] ^ w) * 0x9FB21C651E98DF25ull;
                h[k] ^= h[k] >> 29;
            }
        for (int k = 0; k < 4; ++k) h_[k] = h[k];
    }
};

// Hash of a byte range; about 8 bytes per cycle, strong enough to detect corruption.
inline std::uint64_t hash_bytes(const void* data, std::size_t n, std::uint64_t seed = 0) {
    HashStream h(seed);
    h.add(data, n);
    return h.value();
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
