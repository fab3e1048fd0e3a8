#pragma once
// The registry of table encodings: how each is built from rasterized hits and opened from its
// payload. The renderer and the file format only go through here and the LatticeTable
// interface, so adding an encoding touches nothing else.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lattice/rasterizer.h"
#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

// Error targets for the encodings that quantise (in units of the primitive's sigma, degrees).
struct EncodeOptions {
    double max_point_error = 0.01;
    double max_normal_error_deg = 1.0;
    std::string normals = "auto";  // dense: "oct", "part" or "auto" (the smaller)
};

struct EncodingInfo {
    std::string name;
    std::string summary;
    std::uint64_t max_points;  // boundary points it can key
    double bytes_per_hit;      // for planning memory before a build
    bool needs_hits;           // built from rasterized hits (else from the primitive itself)
};

const std::vector<EncodingInfo>& table_encodings();
// Throws InputError listing the known encodings when `name` is not one.
const EncodingInfo& encoding_info(const std::string& name);

// Builds the payload. `r` holds the rasterized hits for encodings that need them.
ByteBuffer encode_table(const std::string& encoding, const RasterizeResult& r,
                        const TableContext& ctx, const EncodeOptions& opt = {});
// How far (primitive units) a hit stored by the encoding can lie from the primitive's surface
// at most; infinity when it can answer pairs whose segment misses (perfect hashing). The
// renderer culls rays far from the primitive by it without changing any answer.
double hit_error_bound(const std::string& encoding, const TableContext& ctx,
                       const EncodeOptions& opt);
// The table over a payload (which must outlive it); throws std::runtime_error if inconsistent.
std::unique_ptr<LatticeTable> open_table(const std::string& encoding, const std::uint8_t* payload,
                                         std::size_t size, std::uint64_t entries,
                                         const TableContext& ctx);

}  // namespace lat
