#pragma once
// Lattice tables for a scene's primitives: what a table for (primitive, spec) must be, building
// one (with an up-front size check), and the on-disk cache that `render` uses so that a
// lattice-mode render builds each table once and then reuses it.
#include <memory>
#include <string>

#include "lattice/encodings.h"
#include "lattice/rasterizer.h"
#include "lattice/table_file.h"
#include "scene/scene.h"

namespace lat {

// Bump when rasterization semantics change, so cached tables are rebuilt.
inline constexpr int kRasterizerVersion = 3;

// Which table of a primitive: refinement, encoding and its error targets.
struct TableSpec {
    int sigma_inv = 1;
    std::string encoding = "hash14";
    EncodeOptions options;
};

// The header a table for this primitive must carry; throws InputError when the primitive has
// no lattice, sigma_inv is out of range or the encoding is unknown.
TableHeader lattice_header(const Primitive& p, const TableSpec& spec, const std::string& scene_file);
TableContext table_context(const Primitive& p, const TableHeader& h);

// Throws InputError, before any long work, when the table cannot be built here: the primitive
// leaves its lattice box, the encoding cannot key that many points, or the table would not fit
// in memory (the message gives the size it would need).
void check_table_buildable(const Primitive& p, const TableSpec& spec, const std::string& scene_file);

struct TableBuild {
    TableHeader header;
    RasterizeResult raster;  // counts and timing (hits not kept)
    double encode_seconds = 0;
    std::uint64_t bytes = 0;  // the whole file
};

// Rasterizes the primitive, encodes the table and writes it to `path` atomically.
TableBuild build_table_file(const Primitive& p, const TableSpec& spec, const std::string& path,
                            const std::string& scene_file, bool progress);

// The primitive a table file was built for, from the definition stored in its metadata.
Primitive primitive_from_metadata(const TableHeader& h, const std::string& path);

// The default cache directory: $LATTICE_CACHE_DIR, else $XDG_CACHE_HOME/lattice, else
// ~/.cache/lattice.
std::string default_cache_dir();

class TableCache {
public:
    // An explicit directory must exist and be writable; the default one is created.
    TableCache(const std::string& dir, bool explicit_dir);

    const std::string& dir() const { return dir_; }
    std::string path_for(const Primitive& p, const TableSpec& spec, const std::string& scene_file) const;

    struct Entry {
        std::shared_ptr<const LatticeTable> table;
        TableHeader header;
        std::string path;
        bool built = false;
        double build_seconds = 0;
    };
    // Loads the cached table, or builds and caches it.
    Entry get(const Primitive& p, const TableSpec& spec, const std::string& scene_file,
              bool progress) const;

private:
    std::string dir_;
};

// The lattice shapes of every primitive that instances use, from the cache (built on demand).
struct SceneLattices {
    std::vector<std::shared_ptr<const Shape>> shapes;  // per primitive; null if unused
    std::uint64_t table_bytes = 0;
    std::uint64_t table_entries = 0;
    int built = 0;
    double build_seconds = 0;
    std::vector<std::string> paths;
};
SceneLattices scene_lattices(const Scene& scene, const TableCache& cache, const TableSpec& spec,
                             bool progress);

}  // namespace lat
