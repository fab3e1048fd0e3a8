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

struct EncodingInfo {
    std::string name;
    std::string summary;
    std::uint64_t max_points;   // boundary points it can key
    double bytes_per_hit;       // for planning memory before a build
};

const std::vector<EncodingInfo>& table_encodings();
// Throws InputError listing the known encodings when `name` is not one.
const EncodingInfo& encoding_info(const std::string& name);

ByteBuffer encode_table(const std::string& encoding, const RasterizeResult& r);
// The table over a payload (which must outlive it); throws std::runtime_error if inconsistent.
std::unique_ptr<LatticeTable> open_table(const std::string& encoding, const std::uint8_t* payload,
                                         std::size_t size, std::uint64_t entries);

}  // namespace lat
