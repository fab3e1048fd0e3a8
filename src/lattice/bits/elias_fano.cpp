#include "lattice/bits/elias_fano.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

namespace lat {
namespace {

// Position of the r-th (0-based) set bit of x, which has more than r set bits: the byte by
// popcounts, then the bit.
unsigned select_in_word(std::uint64_t x, unsigned r) {
    unsigned shift = 0;
    for (;;) {
        const auto c = static_cast<unsigned>(std::popcount(x & 0xFF));
        if (r < c) break;
        r -= c, x >>= 8, shift += 8;
    }
    for (unsigned k = 0; k < r; ++k) x &= x - 1;
    return shift + static_cast<unsigned>(std::countr_zero(x));
}

}  // namespace

EliasFanoShape EliasFanoShape::for_keys(std::uint64_t n, std::uint64_t universe) {
    EliasFanoShape s;
    s.n = n;
    s.universe = universe;
    s.low_bits = 0;
    // About log2(universe / n) low bits leaves at most 2n buckets; an empty set needs one.
    const std::uint64_t keep = std::max<std::uint64_t>(n, 1);
    while (s.low_bits < 63 && (universe >> (s.low_bits + 1)) >= keep) ++s.low_bits;
    return s;
}

std::vector<std::uint64_t> elias_fano_encode(std::span<const std::uint64_t> keys,
                                             const EliasFanoShape& shape) {
    std::vector<std::uint64_t> out(shape.high_words(), 0);
    BitWriter low(shape.n * shape.low_bits);
    for (std::uint64_t i = 0; i < keys.size(); ++i) {
        const std::uint64_t k = keys[i];
        if (k >= shape.universe || (i > 0 && k <= keys[i - 1]))
            throw std::logic_error("elias_fano_encode: keys not sorted, distinct and in range");
        const std::uint64_t pos = (k >> shape.low_bits) + i;
        out[pos >> 6] |= std::uint64_t{1} << (pos & 63);
        low.put(k, shape.low_bits);
    }
    out.insert(out.end(), low.words().begin(), low.words().end());
    out.resize(shape.high_words() + shape.low_words(), 0);
    return out;
}

EliasFanoView::EliasFanoView(const std::uint64_t* words, const EliasFanoShape& shape)
    : high_(words), low_(words + shape.high_words()), shape_(shape) {
    const std::uint64_t nbits = shape.high_bits(), nwords = shape.high_words();
    std::uint64_t ones = 0;
    for (std::uint64_t w = 0; w < nwords; ++w)
        ones += static_cast<std::uint64_t>(std::popcount(high_[w]));
    const unsigned tail = static_cast<unsigned>(nbits & 63);
    if (ones != shape.n || (tail != 0 && (high_[nwords - 1] >> tail) != 0))
        throw std::runtime_error("learned: exception index is inconsistent");
    if (nbits >= (std::uint64_t{1} << 32))
        throw std::runtime_error("learned: exception set too large");
    // Every 2^kSampleLog-th zero, by a scan of the words.
    std::uint64_t zeros = 0;
    for (std::uint64_t w = 0; w < nwords; ++w) {
        std::uint64_t x = ~high_[w];
        if (w + 1 == nwords && tail != 0) x &= (std::uint64_t{1} << tail) - 1;
        while (x) {
            if ((zeros & ((std::uint64_t{1} << kSampleLog) - 1)) == 0)
                samples_.push_back(static_cast<std::uint32_t>(
                    w * 64 + static_cast<std::uint64_t>(std::countr_zero(x))));
            ++zeros;
            x &= x - 1;
        }
    }
}

std::uint64_t EliasFanoView::select_zero(std::uint64_t j) const {
    const std::uint64_t s = samples_[j >> kSampleLog];
    auto r = static_cast<unsigned>(j & ((std::uint64_t{1} << kSampleLog) - 1));
    if (r == 0) return s;
    std::uint64_t w = (s + 1) >> 6;
    std::uint64_t x = ~high_[w] & (~std::uint64_t{0} << ((s + 1) & 63));
    const std::uint64_t nwords = shape_.high_words();
    for (;;) {
        const auto c = static_cast<unsigned>(std::popcount(x));
        if (r <= c) return w * 64 + select_in_word(x, r - 1);
        r -= c;
        if (++w >= nwords) return shape_.high_bits();  // unreachable for a validated set
        x = ~high_[w];
    }
}

bool EliasFanoView::find(std::uint64_t key, std::uint64_t& rank) const {
    if (shape_.n == 0) return false;
    const std::uint64_t h = key >> shape_.low_bits;
    if (h >= shape_.buckets()) return false;
    const unsigned lb = shape_.low_bits;
    const std::uint64_t want = lb == 0 ? 0 : key & ((std::uint64_t{1} << lb) - 1);
    const std::uint64_t nbits = shape_.high_bits();
    for (std::uint64_t pos = h == 0 ? 0 : select_zero(h - 1) + 1; pos < nbits; ++pos) {
        if (((high_[pos >> 6] >> (pos & 63)) & 1) == 0) return false;  // end of the bucket
        const std::uint64_t i = pos - h;                               // ones before pos
        const std::uint64_t low = read_bits(low_, i * lb, lb);
        if (low == want) {
            rank = i;
            return true;
        }
        if (low > want) return false;
    }
    return false;
}

}  // namespace lat
