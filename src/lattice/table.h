#pragma once
// The Lattice Hash Table interface (paper 2.3): for an ordered pair (p_i, p_o) of boundary grid
// points, the intersection closest to p_i of the segment p_i -> p_o with the primitive, if any.
// The renderer only sees this interface; the encodings (lattice/encoding.h) live behind it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "util/big_buffer.h"

#include "geometry/shape.h"
#include "math/vec.h"

namespace lat {

struct TableHit {
    double t = 0;  // the hit is p_i + t (p_o - p_i), 0 <= t <= 1
    Vec3 normal;   // unit outward normal, lattice (= primitive) orientation
};

// One rasterized intersection, before encoding: what every encoding is built from.
struct RawHit {
    std::uint32_t a = 0, b = 0;  // boundary point ids of p_i and p_o
    float t = 0;
    std::uint16_t nu = 0, nv = 0;  // octahedral normal, 16 bits each
    // The primitive's Crossing (which surface was hit), packed: the part, and the CSG leaf in
    // the low 15 bits with its flip bit on top (20 bytes a hit: tens of millions are kept).
    std::uint16_t part = 0, leaf = 0;

    static constexpr std::uint32_t kMaxPart = 0xFFFF, kMaxLeaf = 0x7FFF;
    static std::uint16_t pack_leaf(std::uint32_t leaf) {
        return static_cast<std::uint16_t>((leaf & kMaxLeaf) | ((leaf & Crossing::kFlipBit) ? 0x8000u : 0u));
    }
    Crossing crossing(double at) const {
        return {at, part, (leaf & kMaxLeaf) | ((leaf & 0x8000u) ? Crossing::kFlipBit : 0u)};
    }
};
static_assert(sizeof(RawHit) == 20);
inline constexpr int kRawNormalBits = 16;

// A hit as the tables keyed by 16-bit point ids store it (hash14): both ids, t quantised
// (quantise_t16) and the octahedral normal. The rasterizer can keep hits in this form, half a
// raw hit, when the encoding asks for no more: fresh memory is dear (first touches, on virtual
// machines above all), and rasterization's hits are most of a build's.
struct PointHit {
    std::uint16_t a, b, t, nu, nv;
};
static_assert(sizeof(PointHit) == 10);

// lround(clamp(t, 0, 1) * 65535) (halves away from zero; NaN as 0), inline: a call into libm
// was a tenth of hash14's build.
inline std::uint16_t quantise_t16(float t) {
    const double x = std::clamp(double(t), 0.0, 1.0) * 65535.0;
    if (!(x >= 0)) return 0;
    const double whole = std::trunc(x);  // x - whole is exact
    // The round-up as a 0 or 1 added, not a branch: it is a coin toss for a table's hits.
    return static_cast<std::uint16_t>(static_cast<int>(whole) + (x - whole >= 0.5 ? 1 : 0));
}

// Rasterized hits in chunks (one per block of entry points, in a fixed order) that point into
// large buffers, so that a big rasterization is never copied or grown piecewise. The buffers
// are made non-const: an encoding that holds the only reference to one may reuse its memory.
template <class Hit>
struct HitChunks {
    std::vector<std::shared_ptr<const ByteBuffer>> storage;
    std::vector<std::span<const Hit>> chunks;

    std::uint64_t size() const {
        std::uint64_t n = 0;
        for (const auto& c : chunks) n += c.size();
        return n;
    }
    std::vector<Hit> flatten() const {
        std::vector<Hit> out;
        out.reserve(size());
        for (const auto& c : chunks) out.insert(out.end(), c.begin(), c.end());
        return out;
    }
};
using RawHits = HitChunks<RawHit>;
using PointHits = HitChunks<PointHit>;

// Sub-rays a pair of a prefiltered table is sampled with (lattice/coverage.h), unless its
// primitive is costly to intersect (coverage_rays_for, the one place that chooses).
inline constexpr int kCoverageRays = 64;
// A count that any prefiltered payload satisfies: a table opened on its own, whose payload says.
inline constexpr int kAnyCoverageRays = 0;

// The lattice a table is for, at its refinement, and the primitive: what rasterizing, building,
// opening and tracing a table need besides its payload (encodings that intersect the primitive
// exactly, or re-evaluate its normals, use it). Derived once from a table's header.
struct TableContext {
    std::array<int, 3> cells{};  // at the refinement
    double cell = 1;             // primitive units per lattice unit (sigma / sigma^-1)
    double sigma = 1;            // the primitive's own grid spacing
    const Shape* primitive = nullptr;
    // Prefiltered tables: the sub-rays a pair is sampled with when building, and required of
    // the payload when opening (kAnyCoverageRays: whatever it records).
    int coverage_rays = kCoverageRays;
};

// The one range of sigma^-1, the refinement of a lattice, for requests and for table files.
inline constexpr int kMaxSigmaInv = 1024;
// Empty when 1 <= k <= kMaxSigmaInv, else "sigma^-1 = K is out of range (1 to 1024)".
inline std::string sigma_inv_error(long long k) {
    if (k >= 1 && k <= kMaxSigmaInv) return {};
    return "sigma^-1 = " + std::to_string(k) + " is out of range (1 to " +
           std::to_string(kMaxSigmaInv) + ")";
}

// A candidate list: part indices in ascending order, pointing into the table's storage (no
// copy a lookup, and no limit on the parts of a primitive).
struct CandidateList {
    int count = 0;
    const std::uint32_t* parts = nullptr;
    std::span<const std::uint32_t> span() const { return {parts, static_cast<std::size_t>(count)}; }
};

// A prefiltered table's answer for a pair (lattice/coverage.h): the share of the rays
// snapping to it that meet the primitive, and their mean hit.
struct CoverageHit {
    double alpha = 0;  // in (0, 1]
    double t = 0;      // the mean hit point, projected on the segment p_a -> p_b
    Vec3 normal;       // the mean of their unit normals: shorter than 1 where they spread
};

class LatticeTable {
public:
    virtual ~LatticeTable() = default;

    // Hit tables answer with the stored hit of a pair; candidate tables with the parts of the
    // primitive that a ray snapping to the pair can meet, which the renderer then intersects
    // exactly with the real ray.
    enum class Kind { kHits, kCandidates };
    virtual Kind kind() const { return Kind::kHits; }

    // The hit closest to p_a on the segment p_a -> p_b, if any (candidate tables intersect
    // their candidates with the segment exactly).
    virtual bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const = 0;
    // The same hit's t alone, for shadow rays (two in three rays on the fur plates): encodings
    // whose normals cost work to decode (dense's part codes evaluate the primitive's gradient)
    // skip it. Answers exactly when lookup() does.
    virtual bool lookup_t(std::uint32_t a, std::uint32_t b, double& t) const {
        TableHit hit;
        if (!lookup(a, b, hit)) return false;
        t = hit.t;
        return true;
    }
    // Candidate tables: the parts for the pair (a, b); false when there are none.
    virtual bool candidates(std::uint32_t, std::uint32_t, CandidateList&) const { return false; }
    // Prefiltered tables (Encoding::coverage): the pair's coverage; false when the pair's rays
    // (nearly) all miss.
    virtual bool coverage(std::uint32_t, std::uint32_t, CoverageHit&) const { return false; }
    // The coverage of n pairs (a[i], b[i]) at once, found[i] saying whether each has one: lets
    // a table overlap the memory accesses of the pairs a smooth filter blends. normals: false
    // when only alpha and t are wanted (shadow rays' transmittance): the normals may be left
    // unset.
    virtual void coverage_many(const std::uint32_t* a, const std::uint32_t* b, int n,
                               CoverageHit* out, bool* found, bool normals) const {
        std::uint64_t ref[16];
        for (int base = 0; base < n; base += 16) {
            const int m = n - base < 16 ? n - base : 16;
            locate_coverage(a + base, b + base, m, ref);
            coverage_at(ref, m, out + base, found + base, normals);
        }
    }
    // coverage_many in two steps, so that the lookups of several tables overlap and pairs are
    // found once: locate_coverage finds the n pairs (ref[i], a handle of the table's, valid
    // while it is) and may start loading what coverage_at, later, reads. By default a handle
    // is the pair itself.
    virtual void locate_coverage(const std::uint32_t* a, const std::uint32_t* b, int n,
                                 std::uint64_t* ref) const {
        for (int i = 0; i < n; ++i) ref[i] = std::uint64_t{a[i]} << 32 | b[i];
    }
    virtual void coverage_at(const std::uint64_t* ref, int n, CoverageHit* out, bool* found,
                             bool /*normals*/) const {
        for (int i = 0; i < n; ++i)
            found[i] = coverage(static_cast<std::uint32_t>(ref[i] >> 32),
                                static_cast<std::uint32_t>(ref[i]), out[i]);
    }

    virtual std::string encoding() const = 0;
    // Encoding-specific facts for `lattice inspect` (widths, counts), one line; may be empty.
    virtual std::string details() const { return {}; }
    // Stored hits, and every byte the table occupies (payload and indices built at open).
    virtual std::uint64_t entries() const = 0;
    virtual std::uint64_t bytes() const = 0;

    // Keeps what the payload lives in (a file mapping) alive as long as the table.
    void hold(std::shared_ptr<const void> storage) { storage_ = std::move(storage); }

private:
    std::shared_ptr<const void> storage_;
};

}  // namespace lat
