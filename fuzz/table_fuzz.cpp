// Lattice table files (.lht) -> inspect's path: the header, the primitive from the metadata,
// the table opened over its payload, lookups of many pairs and, for small lattices, certify.
// The harness forges the checksums of every input (as a hostile file would), so mutations reach
// the validation of the fields and the payload instead of stopping at the checksum. Every input
// must load or throw InputError, and a loaded table must answer every pair in bounds.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "geometry/lattice_source.h"
#include "lattice/boundary_grid.h"
#include "lattice/certify.h"
#include "lattice/table_file.h"
#include "scene/table_metadata.h"
#include "util/error.h"
#include "util/hash.h"

namespace {

// The header's layout (lattice/table_file.cpp): sizes at 88 and 96, the payload checksum at
// 104, the header checksum at 112 over the bytes before it.
constexpr std::size_t kPayloadBytesAt = 88, kMetaBytesAt = 96, kPayloadSumAt = 104,
                      kHeaderSumAt = 112;

std::uint64_t get64(const std::uint8_t* p) {
    std::uint64_t v;
    std::memcpy(&v, p, 8);
    return v;
}

void forge_checksums(std::vector<std::uint8_t>& f) {
    if (f.size() < lat::kTableHeaderBytes) return;
    const std::uint64_t body = f.size() - lat::kTableHeaderBytes;
    const std::uint64_t payload = get64(&f[kPayloadBytesAt]), meta = get64(&f[kMetaBytesAt]);
    if (payload <= body && meta == body - payload) {
        const std::uint8_t* p = f.data() + lat::kTableHeaderBytes;
        const std::uint64_t sum = lat::hash_bytes(p + payload, meta, lat::hash_bytes(p, payload));
        std::memcpy(&f[kPayloadSumAt], &sum, 8);
    }
    const std::uint64_t header = lat::hash_bytes(f.data(), kHeaderSumAt);
    std::memcpy(&f[kHeaderSumAt], &header, 8);
}

void exercise(const std::string& path) {
    const lat::TableHeader h = lat::read_table_header(path);
    const lat::Primitive prim = lat::primitive_from_metadata(h, path);
    const lat::LoadedTable t = lat::load_table_file(path, nullptr, prim.shape.get());
    const lat::BoundaryGrid grid(h.cells);
    const std::uint32_t n = grid.count(), step = std::max<std::uint32_t>(1, n / 64);
    for (std::uint32_t a = 0; a < n; a += step)
        for (std::uint32_t b = 0; b < n; b += step) {
            lat::TableHit hit;
            lat::CandidateList list;
            if (t.table->kind() == lat::LatticeTable::Kind::kCandidates) {
                if (t.table->candidates(a, b, list))
                    for (int k = 0; k < list.count; ++k)
                        if (list.parts[k] >= lat::ShapeSource(*prim.shape).piece_count()) __builtin_trap();
            } else if (t.table->lookup(a, b, hit) && !std::isfinite(hit.t)) {
                __builtin_trap();
            }
        }
    if (lat::BoundaryGrid::pair_count(h.cells) <= 2e4L)
        (void)lat::certify_table(*t.table, h.context(prim.shape.get()), false);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = (std::filesystem::temp_directory_path() /
                                     ("lattice-fuzz-table-" + std::to_string(::getpid()) + ".lht"))
                                        .string();
    std::vector<std::uint8_t> file(data, data + size);
    forge_checksums(file);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    const bool written = std::fwrite(file.data(), 1, file.size(), f) == file.size();
    std::fclose(f);
    if (!written) return 0;
    try {
        exercise(path);
    } catch (const lat::InputError&) {
    }
    return 0;
}
