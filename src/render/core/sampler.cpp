#include "render/core/sampler.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

namespace lat {
namespace {

constexpr std::array<SamplerDescription, 3> kSamplers{{
    {"grid", SamplerKind::kGrid,
     "the centres of the cells of a near-square grid (4 spp: 2 x 2, 6: 2 x 3), alike in every "
     "pixel: the most faithful on the bench scenes"},
    {"sobol", SamplerKind::kSobol,
     "a low-discrepancy sequence (Owen-scrambled Sobol) scrambled anew in each pixel, at 2^m spp "
     "one sample in each of the 2^m columns, the 2^m rows and every elementary interval between: "
     "noise in place of the grid's aliasing"},
    {"jitter", SamplerKind::kJitter,
     "one uniformly random point in each cell of the grid (stratified jitter)"},
}};

// A well-mixed hash (splitmix64 finaliser): randomness that depends on the pixel and sample only.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

// The top 53 bits as a double in [0,1).
double unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }
double unit32(std::uint32_t h) { return static_cast<double>(h) * 0x1.0p-32; }

std::uint32_t reverse_bits(std::uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

// Owen's nested uniform scrambling by Burley's hash ("Practical Hash-based Owen Scrambling",
// JCGT 2020, after Laine and Karras): on the bit-reversed fraction, adding the seed and
// x ^= x * even only carry from lower bits to higher, so each digit of the fraction is flipped
// by a function of the digits before it alone, which keeps every elementary interval's count.
std::uint32_t owen_scramble(std::uint32_t x, std::uint32_t seed) {
    x = reverse_bits(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverse_bits(x);
}

// The second dimension of Sobol's sequence: its generator matrix is Pascal's triangle mod 2.
std::uint32_t sobol_dim1(std::uint32_t k) {
    std::uint32_t r = 0;
    for (std::uint32_t v = 1u << 31; k != 0; k >>= 1, v ^= v >> 1)
        if (k & 1u) r ^= v;
    return r;
}

// The Sobol sampler's stream of the pixel hash, apart from the jitter's.
constexpr std::uint64_t kSobolStream = 0x5ab01u;

}  // namespace

std::span<const SamplerDescription> samplers() { return kSamplers; }

const SamplerDescription& sampler_description(SamplerKind kind) {
    for (const SamplerDescription& d : kSamplers)
        if (d.kind == kind) return d;
    return kSamplers.front();
}

void stratify(int n, int& nx, int& ny) {
    nx = static_cast<int>(std::sqrt(static_cast<double>(n)));
    while (nx > 1 && n % nx != 0) --nx;
    ny = n / nx;
}

std::array<std::uint32_t, 2> owen_sobol(std::uint32_t k, std::uint64_t scramble) {
    return {owen_scramble(reverse_bits(k), static_cast<std::uint32_t>(scramble)),
            owen_scramble(sobol_dim1(k), static_cast<std::uint32_t>(scramble >> 32))};
}

PixelSampler::PixelSampler(SamplerKind kind, int spp) : kind_(kind), spp_(std::max(1, spp)) {
    stratify(spp_, nx_, ny_);
}

std::array<double, 2> PixelSampler::offset(std::uint64_t pixel, int k) const {
    assert(k >= 0 && k < spp_);
    if (spp_ == 1) return {0.5, 0.5};
    switch (kind_) {
        case SamplerKind::kJitter: {
            const std::uint64_t h = mix(pixel * 1024 + static_cast<std::uint64_t>(k));
            return {((k % nx_) + unit(h)) / nx_, ((k / nx_) + unit(mix(h))) / ny_};
        }
        case SamplerKind::kGrid:
            return {((k % nx_) + 0.5) / nx_, ((k / nx_) + 0.5) / ny_};
        case SamplerKind::kSobol: {
            const auto p = owen_sobol(static_cast<std::uint32_t>(k), mix(pixel ^ (kSobolStream << 40)));
            return {unit32(p[0]), unit32(p[1])};
        }
    }
    return {0.5, 0.5};
}

}  // namespace lat
