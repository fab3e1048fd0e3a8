#pragma once
// The Table 1 file (the format of examples/table1.json, docs/table1.md): rows of a primitive,
// its box and the paper's printed values per refinement.
#include <string>
#include <vector>

#include "lattice/table1.h"

namespace lat {

// Reads the file and counts every row (lattice/table1.h); throws InputError naming the file and
// the place for a malformed file or a cell too large to count.
std::vector<Table1Row> compute_table1(const std::string& path, bool progress);

}  // namespace lat
