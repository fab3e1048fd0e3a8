#pragma once
// Where a pixel's camera samples fall: the samplers `render --sampler` offers, each a pure
// function of the pixel's index (its seed) and the sample's, so an image is the same bytes for
// any thread and MPI rank count. One sample per pixel is always the pixel's centre.
#include <array>
#include <cstdint>
#include <span>
#include <string_view>

namespace lat {

enum class SamplerKind {
    kJitter,  // one uniform random point in each cell of the near-square grid (stratify)
    kGrid,    // the centre of each cell of that grid
    kSobol,   // the 2-D Sobol (0,2)-sequence, Owen-scrambled per pixel
};

struct SamplerDescription {
    std::string_view name;
    SamplerKind kind;
    std::string_view help;
};

std::span<const SamplerDescription> samplers();
const SamplerDescription& sampler_description(SamplerKind kind);

// The default: the most faithful at 2 to 16 spp on the bench scenes (bench/samplers.py), by 2 to
// 4 dB over random points; it trades their noise for aliasing alike in every pixel.
constexpr SamplerKind kDefaultSampler = SamplerKind::kGrid;

// The sampler of a many-sample truth that another sampler is measured against: independent
// random points, so that the truth holds none of the other's samples (a prefix of a sequence
// would).
constexpr SamplerKind kTruthSampler = SamplerKind::kJitter;

// The sample grid for n samples: nx * ny = n with nx, ny as close as possible.
void stratify(int n, int& nx, int& ny);

// The offsets of a pixel's samples from its corner, each in [0,1)^2.
class PixelSampler {
public:
    PixelSampler(SamplerKind kind, int spp);

    SamplerKind kind() const { return kind_; }
    int spp() const { return spp_; }
    // Sample k (0 <= k < spp) of the pixel with index `pixel` (row-major in the image).
    std::array<double, 2> offset(std::uint64_t pixel, int k) const;

private:
    SamplerKind kind_;
    int spp_, nx_, ny_;
};

// Point k of the 2-D Sobol (0,2)-sequence, Owen-scrambled by `scramble` (one per pixel), as
// 32-bit fractions: every power-of-two prefix of it is a (0,m,2)-net in base 2.
std::array<std::uint32_t, 2> owen_sobol(std::uint32_t k, std::uint64_t scramble);

}  // namespace lat
