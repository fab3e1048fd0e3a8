#pragma once
// The on-disk cache of lattice tables that `render` uses, so that a lattice-mode render builds
// each table once and then reuses it. A table's file name carries its plan's fingerprint.
#include <chrono>
#include <memory>
#include <string>

#include "lattice/cache/table_spec.h"

namespace lat {

// The default cache directory: $LATTICE_CACHE_DIR, else $XDG_CACHE_HOME/lattice, else
// ~/.cache/lattice.
std::string default_cache_dir();

class TableCache {
public:
    // The directory (given or the default) is created when missing and must be writable.
    // across_ranks (collective, in an MPI job): every rank opens the cache and gets the same
    // tables in the same order; a missing table is built once, by all ranks together
    // (rasterized across them, encoded and written by rank 0), and every rank then maps the
    // file, so the directory must be one that all ranks share.
    explicit TableCache(const std::string& dir, bool across_ranks = false);

    const std::string& dir() const { return dir_; }
    std::string path_for(const TablePlan& plan) const;

    struct Entry {
        std::shared_ptr<const LatticeTable> table;
        TableHeader header;
        std::string path;
        std::uint64_t bytes = 0;  // the table's, with its file's header and metadata
        bool built = false;
        double build_seconds = 0;
    };
    // Whether the plan's table is in the cache (collective across ranks: rank 0's answer, the
    // one get acts on).
    bool cached(const TablePlan& plan) const;
    // Loads the cached table, or builds and caches it.
    Entry get(const TablePlan& plan, bool progress) const;

    // Temporaries of killed table writes older than this are removed when a cache is opened.
    static constexpr std::chrono::minutes kStaleTemporary{10};

private:
    std::string dir_;
    bool across_ranks_ = false;

    void open_dir() const;
    void remove_stale_temporaries() const;
    void load(const TablePlan& plan, Entry& e) const;
};

}  // namespace lat
