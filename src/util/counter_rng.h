#pragma once
// A counter-based random stream: draw k of stream s under a seed is a pure function of (seed, s,
// k), mixed by splitmix64's finaliser. Unlike std distributions (whose output the standard
// leaves to each library), it gives the same numbers on every machine, compiler and thread
// count, and any stream can be drawn without drawing the others.
#include <cstdint>

#include "util/hash.h"

namespace lat {

class CounterRng {
public:
    CounterRng(std::uint64_t seed, std::uint64_t stream)
        : key_(mix64(seed ^ mix64(stream + 0x9E3779B97F4A7C15ull))) {}

    std::uint64_t next() { return mix64(key_ + 0x9E3779B97F4A7C15ull * ++counter_); }
    // Uniform in [0, 1): the top 53 bits, exactly representable.
    double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

private:
    std::uint64_t key_;
    std::uint64_t counter_ = 0;
};

}  // namespace lat
