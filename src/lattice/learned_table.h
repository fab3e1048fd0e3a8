#pragma once
// The learned encoding: the paper's 5.2.2 "stochastic lattice hash function", with bounded
// error. A fitted function predicts each pair's answer; an exception list corrects it wherever
// it is wrong or outside the error bounds, so the table as a whole is within them.
//   model      per ordered pair of faces (fa, fb), the hit data sampled on a coarse sub-grid
//              of both faces (every s-th point, and the last), quantised; a pair (a, b) is
//              predicted from the 16 coarse pairs around it by multilinear weights in the 4-D
//              space of face coordinates: a hit when the hit samples outweigh the misses, t
//              and the normal interpolated over the hit samples (the normal in 3-D, normalised).
//   exceptions two Elias-Fano key sets over the pairs: "miss" (the model hits, the pair does
//              not) and "hit" (the model misses or errs), the latter with t and an octahedral
//              normal quantised at the narrowest widths that meet the bounds.
// The build tries several steps and model widths and keeps the smallest table. Documented in
// docs/encoding-learned.md.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lattice/boundary_grid.h"
#include "lattice/learned_bits.h"
#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

struct EncodeOptions;

// Where one fine coordinate lies between coarse nodes j0 and j0 + 1: w1 is the weight of
// j0 + 1 (that of j0 is 1 - w1).
struct AxisCell {
    int j0 = 0;
    double w1 = 0;
};

// The coarse sub-grids at step s, and the numbering of samples and pair keys.
class LearnedLayout {
public:
    struct Face {
        int ua, va;  // the face's in-plane axes
        int nu, nv;  // fine points along them
        int cu, cv;  // coarse nodes: 0, s, 2s, ... and the last point
        std::uint64_t points() const { return std::uint64_t(nu) * std::uint64_t(nv); }
        std::uint64_t nodes() const { return std::uint64_t(cu) * std::uint64_t(cv); }
    };

    LearnedLayout(std::array<int, 3> cells, int step);

    int step() const { return step_; }
    const Face& face(int f) const { return faces_[static_cast<std::size_t>(f)]; }
    AxisCell axis_cell(int u, int n, int c) const {
        const int j0 = std::min(u / step_, c - 2);
        const int u0 = j0 * step_, u1 = std::min(u0 + step_, n - 1);
        return {j0, double(u - u0) / double(u1 - u0)};
    }
    // Samples and keys of face pair (fa, fb), fa != fb, start at these offsets.
    std::uint64_t sample_base(int fa, int fb) const { return sample_base_[idx(fa, fb)]; }
    std::uint64_t key_base(int fa, int fb) const { return key_base_[idx(fa, fb)]; }
    std::uint64_t samples() const { return samples_; }
    std::uint64_t keys() const { return keys_; }

    // The face pair that owns a valid pair of points with face masks ma, mb: the lowest face
    // of each, unless they are the same face (then the next face of b, else of a).
    static void owner(std::uint8_t ma, std::uint8_t mb, int& fa, int& fb);

private:
    int step_;
    std::array<Face, 6> faces_{};
    std::array<std::uint64_t, 36> sample_base_{}, key_base_{};
    std::uint64_t samples_ = 0, keys_ = 0;
    static std::size_t idx(int fa, int fb) { return static_cast<std::size_t>(fa * 6 + fb); }
};

// A decoded coarse sample.
struct LearnedSample {
    bool hit = false;
    double t = 0;
    Vec3 n;
};

// The model's prediction from 16 weighted samples (a weight of 0 skips its sample). One
// compiled copy serves the build and lookups, so the build checks exactly what lookups return.
bool learned_predict(const double w[16], const LearnedSample* const s[16], TableHit& out);
// Multilinear weights of the 16 corners: bit 0 a's u, bit 1 a's v, bit 2 b's u, bit 3 b's v.
void learned_weights(const AxisCell& au, const AxisCell& av, const AxisCell& bu,
                     const AxisCell& bv, double w[16]);

// Field widths of a table (bits).
struct LearnedWidths {
    unsigned model_t = 0, model_n = 0;  // a sample: t (all ones: a miss), normal u and v
    unsigned ex_t = 0, ex_n = 0;        // a hit exception: t, normal u and v
};

// What a build chose and found, for reports.
struct LearnedStats {
    int step = 0;
    LearnedWidths widths;
    std::uint64_t hits = 0, hit_exceptions = 0, miss_exceptions = 0;
    std::uint64_t model_bytes = 0, exception_bytes = 0, total_bytes = 0;
    double seconds = 0;
    std::vector<std::string> trials;  // one line per step and widths tried
};

class LearnedTable final : public LatticeTable {
public:
    static constexpr std::uint32_t kMaxPoints = 0xFFFFFFFFu;

    // From rasterized hits; ctx gives the lattice, sigma and (if set) the primitive, whose
    // exact normals the bounds are checked against (else the hits' own 16-bit normals, with a
    // margin). Parallel and deterministic.
    static ByteBuffer build(const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt,
                            LearnedStats* stats = nullptr);
    // Over a payload made by build (owned or memory-mapped; it must outlive the table); throws
    // std::runtime_error when it is inconsistent or made for other cells than ctx.cells.
    LearnedTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                 const TableContext& ctx);

    bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const override;
    std::string encoding() const override { return "learned"; }
    std::uint64_t entries() const override { return entries_; }
    std::uint64_t bytes() const override;

    int step() const { return layout_.step(); }
    const LearnedWidths& widths() const { return widths_; }
    std::uint64_t hit_exceptions() const { return hit_ex_.size(); }
    std::uint64_t miss_exceptions() const { return miss_ex_.size(); }

private:
    BoundaryGrid grid_;
    LearnedLayout layout_;
    LearnedWidths widths_;
    const std::uint64_t* model_ = nullptr;
    const std::uint64_t* values_ = nullptr;
    EliasFanoView miss_ex_, hit_ex_;
    std::uint64_t entries_;
    std::size_t size_;
};

}  // namespace lat
