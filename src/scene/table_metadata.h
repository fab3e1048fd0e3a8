#pragma once
// A table file names the primitive it was built for: its definition is stored in the file's
// metadata, so `lattice inspect` can rebuild the primitive without the scene.
#include <string>

#include "lattice/primitive.h"
#include "lattice/table_file.h"

namespace lat {

// Throws InputError naming `path` when the metadata does not describe a primitive.
Primitive primitive_from_metadata(const TableHeader& h, const std::string& path);

}  // namespace lat
