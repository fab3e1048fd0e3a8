#include "lattice/encodings/perfect/perfect_table.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "lattice/octahedral.h"

namespace lat {
namespace {

constexpr std::size_t kHeader = 24;

std::uint64_t fingerprint(std::uint64_t key, int bits) {
    return BBHash::key_hash(key) & ((std::uint64_t{1} << bits) - 1);
}

void check_bits(int fingerprint_bits) {
    if (fingerprint_bits != 0 && fingerprint_bits != 8 && fingerprint_bits != 16)
        throw std::invalid_argument("perfect: fingerprint bits must be 0, 8 or 16");
}

}  // namespace

std::string PerfectTable::name(int fingerprint_bits) {
    return "perfect" + std::to_string(entry_bytes(fingerprint_bits));
}

ByteBuffer PerfectTable::build(const RawHits& hits, int fingerprint_bits) {
    check_bits(fingerprint_bits);
    const std::uint64_t n = hits.size();
    const std::size_t nchunks = hits.chunks.size();
    std::vector<std::uint64_t> first(nchunks + 1, 0);
    for (std::size_t c = 0; c < nchunks; ++c) first[c + 1] = first[c] + hits.chunks[c].size();
    std::vector<std::uint64_t> mphf_words;
    {
        std::vector<std::uint64_t> keys(n);
        tbb::parallel_for(std::size_t{0}, nchunks, [&](std::size_t c) {
            std::uint64_t i = first[c];
            for (const RawHit& h : hits.chunks[c]) keys[i++] = key(h.a, h.b);
        });
        mphf_words = BBHash::build(keys);
    }
    const std::size_t mphf_bytes = mphf_words.size() * 8;
    const int stride = entry_bytes(fingerprint_bits);
    ByteBuffer payload(kHeader + mphf_bytes + n * stride);
    const std::uint32_t bits32 = static_cast<std::uint32_t>(fingerprint_bits), zero = 0;
    std::memcpy(payload.data(), &n, 8);
    std::memcpy(payload.data() + 8, &bits32, 4);
    std::memcpy(payload.data() + 12, &zero, 4);
    std::memcpy(payload.data() + 16, &mphf_bytes, 8);
    std::memcpy(payload.data() + kHeader, mphf_words.data(), mphf_bytes);
    const BBHash mphf(payload.data() + kHeader, mphf_bytes);
    std::uint8_t* entries = payload.data() + kHeader + mphf_bytes;
    // Each pair owns its slot (the MPHF is a bijection), so chunks fill in parallel.
    tbb::parallel_for(std::size_t{0}, nchunks, [&](std::size_t c) {
        const std::span<const RawHit> chunk = hits.chunks[c];
        constexpr std::size_t kAhead = 16;
        for (std::size_t i = 0; i < chunk.size(); ++i) {
            if (i + kAhead < chunk.size())
                mphf.prefetch(key(chunk[i + kAhead].a, chunk[i + kAhead].b));
            const RawHit& h = chunk[i];
            const std::uint64_t k = key(h.a, h.b);
            std::uint8_t* e = entries + mphf(k) * stride;
            const auto t = static_cast<std::uint16_t>(
                std::lround(std::clamp(double(h.t), 0.0, 1.0) * 65535.0));
            const Oct o = oct_encode_precise(oct_decode({h.nu, h.nv}, kRawNormalBits), kNormalBits);
            const std::uint32_t n24 = o.u | (o.v << kNormalBits);
            const std::uint64_t fp = fingerprint(k, fingerprint_bits);
            std::memcpy(e, &t, 2);
            std::memcpy(e + 2, &n24, 3);  // little-endian: the low three bytes
            std::memcpy(e + 5, &fp, fingerprint_bits / 8);
        }
    });
    return payload;
}

PerfectTable::PerfectTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                           int fingerprint_bits)
    : fp_bits_(fingerprint_bits), stride_(entry_bytes(fingerprint_bits)), size_(size) {
    check_bits(fingerprint_bits);
    if (size < kHeader) throw std::runtime_error("perfect: payload too small");
    std::uint64_t n, mphf_bytes;
    std::uint32_t bits, zero;
    std::memcpy(&n, payload, 8);
    std::memcpy(&bits, payload + 8, 4);
    std::memcpy(&zero, payload + 12, 4);
    std::memcpy(&mphf_bytes, payload + 16, 8);
    if (n != entries) throw std::runtime_error("perfect: payload holds another number of hits");
    if (bits != static_cast<std::uint32_t>(fingerprint_bits) || zero != 0)
        throw std::runtime_error("perfect: payload has another entry layout");
    if (mphf_bytes > size - kHeader || n >= (std::uint64_t{1} << 32) ||
        size - kHeader - mphf_bytes != n * stride_)
        throw std::runtime_error("perfect: inconsistent payload size");
    mphf_.emplace(payload + kHeader, mphf_bytes);  // validates: its values are below its keys
    if (mphf_->keys() != n)
        throw std::runtime_error("perfect: hash function for another key count");
    e_ = payload + kHeader + mphf_bytes;
}

bool PerfectTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    const std::uint64_t k = key(a, b), i = (*mphf_)(k);
    if (i == BBHash::kNone) return false;
    const std::uint8_t* e = e_ + i * stride_;
    if (fp_bits_) {
        std::uint64_t fp = 0;
        std::memcpy(&fp, e + 5, fp_bits_ / 8);
        if (fp != fingerprint(k, fp_bits_)) return false;
    }
    std::uint16_t t;
    std::uint32_t n24 = 0;
    std::memcpy(&t, e, 2);
    std::memcpy(&n24, e + 2, 3);
    constexpr std::uint32_t mask = (1u << kNormalBits) - 1;
    hit.t = t * (1.0 / 65535.0);
    hit.normal = oct_decode({n24 & mask, (n24 >> kNormalBits) & mask}, kNormalBits);
    return true;
}

}  // namespace lat
