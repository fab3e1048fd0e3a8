#pragma once
// A certified error report for a lattice table: every valid ordered pair of boundary points is
// looked up and compared with exact intersection of its segment with the primitive.
#include <cstdint>

#include "lattice/table.h"

namespace lat {

struct CertifyReport {
    std::uint64_t pairs = 0;         // valid ordered pairs checked
    std::uint64_t exact_hits = 0;    // pairs whose segment meets the primitive
    std::uint64_t false_hits = 0;    // the table hits, the primitive does not
    std::uint64_t false_misses = 0;  // the primitive is hit, the table misses
    // Over pairs that both hit: the distance between the table's point and the exact one (in
    // units of the primitive's sigma), and the angle between normals (degrees).
    double max_point_error = 0, mean_point_error = 0;
    double max_normal_error_deg = 0, mean_normal_error_deg = 0;
    double seconds = 0;
};

// Certification is exhaustive: lattices with more point pairs than this (hours of work) are
// refused by `lattice inspect` unless certification is skipped.
inline constexpr double kMaxCertifyPairs = 2e10;

// ctx.primitive must be set. Parallel over entry points.
CertifyReport certify_table(const LatticeTable& table, const TableContext& ctx, bool progress);

}  // namespace lat
