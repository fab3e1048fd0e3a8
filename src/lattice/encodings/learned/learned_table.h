#pragma once
// The learned encoding: the paper's 5.2.2 "stochastic lattice hash function", with bounded
// error. A function fitted to the rasterized hits predicts each pair's answer; an exception
// list corrects it wherever it is wrong or outside the error bounds, so that the table as a
// whole is within them (certify_table checks every pair).
//   model       a signed distance field fitted to the hits, marched along the pair's segment
//               (learned_field.h)
//   exceptions  two Elias-Fano sets of pair keys a * points + b: "hits" (the model misses, or
//               errs in both t and the normal: both stored) and "corrections" of a predicted
//               hit: a miss, or the normal or t alone; values at the narrowest widths that meet
//               the bounds
// The build tries several node spacings and widths and keeps the smallest table. Payload and
// measurements: docs/encoding-learned.md.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lattice/boundary_grid.h"
#include "lattice/bits/elias_fano.h"
#include "lattice/encodings/learned/learned_field.h"
#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

struct EncodeOptions;

// What a build chose and found, for reports.
struct LearnedStats {
    int nodes_per_sigma = 0;
    FieldShape field;
    std::uint64_t dense_bricks = 0;
    unsigned ex_t = 0, ex_n = 0;
    std::uint64_t hits = 0;
    std::uint64_t miss_exceptions = 0, hit_exceptions = 0, normal_exceptions = 0, t_exceptions = 0;
    std::uint64_t model_bytes = 0, exception_bytes = 0, total_bytes = 0;
    double seconds = 0;
    std::vector<std::string> trials;  // one line per parameter set tried
};

class LearnedTable final : public LatticeTable {
public:
    static constexpr std::uint32_t kMaxPoints = 0xFFFFFFFFu;

    // From rasterized hits; ctx gives the lattice, sigma and (if set) the primitive, whose
    // exact normals the bounds are checked against (else the hits' own 16-bit normals, with a
    // margin). Parallel; the payload does not depend on the thread count.
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

    const FieldShape& field() const { return field_.shape(); }
    std::uint64_t hit_exceptions() const { return hits_.size(); }
    std::uint64_t corrections() const { return corrections_.size(); }
    // The model's own answer, without the exceptions.
    bool predict(std::uint32_t a, std::uint32_t b, TableHit& hit) const;

private:
    BoundaryGrid grid_;
    FieldView field_;
    unsigned ex_t_ = 0, ex_n_ = 0;
    EliasFanoView hits_, corrections_;
    const std::uint64_t* hit_values_ = nullptr;
    const std::uint64_t* records_ = nullptr;
    std::uint64_t entries_;
    std::size_t size_;
};

}  // namespace lat
