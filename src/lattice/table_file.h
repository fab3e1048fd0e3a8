#pragma once
// The lattice table file (.lht), documented in docs/lattice-tables.md:
//   a 128-byte little-endian header — magic "LATTICE\x1a", format version, header size,
//   encoding name, lattice geometry (cells at the refinement, sigma, sigma^-1, cell size), the
//   fingerprint of the primitive it was built for, counts (N_lp, stored hits), payload and
//   metadata sizes, their checksum, header checksum — followed by the encoding's payload and
//   the metadata (JSON).
// Loading checks all of it and rejects a truncated, corrupt or mismatched file with a message
// naming the file and what is wrong. The payload is memory-mapped, not copied.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lattice/encoding.h"
#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

struct TableHeader {
    std::string encoding;
    std::array<int, 3> cells{};  // at the refinement
    int sigma_inv = 1;
    double sigma = 1;  // the primitive's own grid spacing
    double cell = 1;   // sigma / sigma_inv
    std::uint64_t fingerprint = 0;
    std::uint64_t pairs = 0;    // N_lp by eq. (2)
    std::uint64_t entries = 0;  // stored hits
    std::uint64_t payload_bytes = 0;
    // JSON, after the payload: the primitive's name and definition and the scene it came from,
    // so that a table file can be inspected on its own.
    std::string metadata;
    // Prefiltered encodings: the sub-rays a pair (TableContext::coverage_rays). Not a field of
    // the file's header: the payload records it and the fingerprint includes it, so a header
    // read from a file says kAnyCoverageRays.
    int coverage_rays = kCoverageRays;

    TableContext context(const Shape* primitive) const {
        return {cells, cell, sigma, primitive, coverage_rays};
    }
    // "hash14, 28 x 12 x 28 cells (sigma 0.1, sigma^-1 4)", for messages.
    std::string describe() const;
};

inline constexpr std::uint32_t kTableFormatVersion = 1;
inline constexpr std::size_t kTableHeaderBytes = 128;
// Larger files are refused before reading: the largest tables the renderer builds are a few
// GB, and a table is held in memory whole.
inline constexpr std::uint64_t kMaxTableFileBytes = std::uint64_t{64} << 30;

// Writes atomically (temporary file + rename); throws InputError naming the path.
void write_table_file(const std::string& path, const TableHeader& h,
                      const ByteBuffer& payload);
// The same file, its payload written by `fill` into a sink that puts each piece straight into
// the file (so that the payload never needs memory of its own); returns the payload's size.
std::uint64_t write_table_file(const std::string& path, const TableHeader& h,
                               const std::function<void(PayloadSink&)>& fill);

// A table loaded from disk, with the mapping that holds its payload.
struct LoadedTable {
    TableHeader header;
    std::shared_ptr<const LatticeTable> table;
    std::uint64_t bytes = 0;  // the table's, with the file's header and metadata
};

// Reads just the header (validated); throws InputError.
TableHeader read_table_header(const std::string& path);
// Loads and validates a whole file; `expected`, when given, must match its encoding,
// geometry and fingerprint (a table built for another primitive is rejected). `primitive` is
// what encodings that intersect it exactly use (null: the table's lookups may be unusable).
LoadedTable load_table_file(const std::string& path, const TableHeader* expected = nullptr,
                            const Shape* primitive = nullptr);

}  // namespace lat
