#pragma once
// Which table of a primitive: what the user asks for (TableSpec), resolved once per primitive
// into a TablePlan from which the file header, its fingerprint, the cache name, the build and
// the lattice shape are all derived.
#include <string>

#include "lattice/encoding.h"
#include "lattice/primitive.h"
#include "lattice/table_file.h"

namespace lat {

// Bump when rasterization semantics change, so cached tables are rebuilt.
inline constexpr int kRasterizerVersion = 3;

// Throws InputError "WHERE: " + sigma_inv_error(k) when k is out of range.
void check_sigma_inv(long long k, const std::string& where);

// The user's choice: refinement, encoding and its error targets.
struct TableSpec {
    int sigma_inv = 1;
    std::string encoding = "hash14";
    EncodeOptions options;
};

struct TablePlan {
    const Primitive* primitive = nullptr;  // must outlive the plan
    const Encoding* encoding = nullptr;
    EncodeOptions options;
    TableHeader header;    // what the table's file must say, fingerprint and metadata included
    TableContext context;  // the lattice at the refinement, and the primitive's shape
    std::string place;     // "scene.json: primitives.hair: ", to begin messages with

    double error_bound() const { return encoding->error_bound(context, options); }
};

// Throws InputError when the primitive has no lattice, sigma^-1 is out of range or the
// encoding is unknown.
TablePlan plan_table(const Primitive& p, const TableSpec& spec, const std::string& scene_file);

}  // namespace lat
