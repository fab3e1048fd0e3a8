#pragma once
// A table encoding is one descriptor: its name, its limits, and how it is built, opened and
// bounded. Each lives in its own folder (lattice/encodings/<name>/) and is listed once, in
// lattice/encodings/registry.cpp; everything else finds it by name through find_encoding and
// then only goes through the descriptor and the LatticeTable interface.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

// How `dense` stores normals: octahedral codes, the part hit (its normal re-evaluated at the
// decoded point), or whichever is smaller (auto; octahedral codes where a part's normal is not
// cheap to re-evaluate: quartic surfaces).
enum class DenseNormals { kAuto, kOct, kPart };
// Their option names, "auto", "oct" and "part": the one place they are spelled.
inline constexpr std::array<std::pair<std::string_view, DenseNormals>, 3> kDenseNormalNames{
    {{"auto", DenseNormals::kAuto}, {"oct", DenseNormals::kOct}, {"part", DenseNormals::kPart}}};

// Error targets for the encodings that quantise (in units of the primitive's sigma, degrees).
struct EncodeOptions {
    double max_point_error = 0.01;
    double max_normal_error_deg = 1.0;
    DenseNormals normals = DenseNormals::kAuto;
    // Bytes a build may hold at its peak, 0 for no limit: encodings whose size the plan cannot
    // foresee from the hits (`candidates`: lists grow with the parts near each pair) stop with
    // an InputError past it. Not part of the table: a build fits or is refused.
    std::size_t memory_budget = 0;
    // Whether a long build (coverage: its sub-rays) shows a progress bar. Not part of the table.
    bool progress = false;
};

// Where an encoding's payload goes: its size first, then pieces at byte offsets, in any order,
// each byte written once, from one thread at a time. A table file (lattice/table_file.h) takes
// it straight into the file, so that a large payload never needs memory of its own.
class PayloadSink {
public:
    virtual ~PayloadSink() = default;
    virtual void reserve(std::size_t size) = 0;  // once, before any piece
    virtual void write_at(std::size_t offset, const void* data, std::size_t n) = 0;
};

// A sink into memory.
class BufferSink final : public PayloadSink {
public:
    void reserve(std::size_t size) override { buffer_ = ByteBuffer(size); }
    void write_at(std::size_t offset, const void* data, std::size_t n) override;
    ByteBuffer take() { return std::move(buffer_); }

private:
    ByteBuffer buffer_;
};

struct Encoding {
    std::string_view name;
    std::string_view summary;
    LatticeTable::Kind kind = LatticeTable::Kind::kHits;
    std::uint64_t max_points = 0;  // boundary points it can key
    double bytes_per_hit = 0;      // at the build's peak, for planning memory before a build
    bool needs_hits = true;        // built from rasterized hits (else from the primitive itself)
    // Stores each pair's coverage besides its hit (LatticeTable::coverage): the tables that
    // filtered rendering (--filter) can use.
    bool coverage = false;
    // The payload's layout, bumped when it changes (or when a build with the same options
    // writes another table). It is part of a table's fingerprint, so that a cached table of
    // another layout is rebuilt (its file name differs), not misread or kept stale.
    int layout = 1;

    // The payload. `hits` are the rasterized hits when needs_hits (else empty); ctx.primitive
    // is set. Must not depend on the thread count.
    ByteBuffer (*build)(const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt);
    // Optional: the same payload written into a sink, consuming the hits (an encoding frees
    // them as soon as it has read them), for encodings whose build would otherwise hold the
    // hits, a copy of them and the payload at once. encode_payload chooses between the two.
    void (*stream)(RawHits&& hits, const TableContext& ctx, const EncodeOptions& opt,
                   PayloadSink& sink) = nullptr;
    // Optional: the same payload from the hits as PointHits (rasterized in that form, half the
    // memory of raw hits), for encodings that store no more of a hit; a build that rasterizes
    // in one process uses it when set.
    void (*stream_points)(PointHits&& hits, const TableContext& ctx, const EncodeOptions& opt,
                          PayloadSink& sink) = nullptr;
    // The table over a payload (which must outlive it); throws std::runtime_error when the
    // payload is inconsistent.
    std::unique_ptr<LatticeTable> (*open)(const std::uint8_t* payload, std::size_t size,
                                          std::uint64_t entries, const TableContext& ctx);
    // How far (primitive units) a stored hit can lie from the primitive's surface at most;
    // infinity when it can answer pairs whose segment misses (perfect hashing). The renderer
    // culls rays far from the primitive by it without changing any answer.
    double (*error_bound)(const TableContext& ctx, const EncodeOptions& opt);
};

// The payload of `enc` for the hits, into the sink: through its stream when it has one, else
// its build (then copied in). Byte for byte the payload build gives.
void encode_payload(const Encoding& enc, RawHits&& hits, const TableContext& ctx,
                    const EncodeOptions& opt, PayloadSink& sink);

// Every registered encoding, in the order they are listed to users.
std::span<const Encoding* const> encodings();
// Throws InputError listing the known encodings when `name` is not one.
const Encoding& find_encoding(std::string_view name);
// The encoding filtered lattices use: the first that stores coverage.
const Encoding& coverage_encoding();

}  // namespace lat
