#include "lattice/cache/table_cache.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "distributed/job.h"
#include "lattice/cache/table_build.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace lat {

std::string default_cache_dir() {
    if (const char* d = std::getenv("LATTICE_CACHE_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/lattice";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::string(home) + "/.cache/lattice";
    return ".lattice-cache";
}

TableCache::TableCache(const std::string& dir, bool across_ranks)
    : dir_(dir), across_ranks_(across_ranks && dist::distributed()) {
    if (!across_ranks_) {
        open_dir();
        remove_stale_temporaries();
        return;
    }
    // Rank 0 first, so that only it creates a missing directory.
    dist::on_root([&] {
        open_dir();
        remove_stale_temporaries();
    });
    dist::agree([&] {
        if (!dist::is_root()) open_dir();
    });
}

void TableCache::open_dir() const {
    struct stat st {};
    if (::stat(dir_.c_str(), &st) != 0) {
        std::error_code ec;
        std::filesystem::create_directories(dir_, ec);
        if (ec)
            throw InputError(dir_ + ": cannot create the lattice cache directory: " + ec.message());
    } else if (!S_ISDIR(st.st_mode)) {
        throw InputError(dir_ + ": lattice cache is not a directory");
    }
    if (::access(dir_.c_str(), R_OK | W_OK | X_OK) != 0)
        throw InputError(dir_ + ": lattice cache directory is not readable and writable: " +
                         std::strerror(errno));
}

// A table is written whole into TARGET.tmp-XXXXXX and renamed (util/atomic_file.h). A coverage
// build creates its temporary before it computes for minutes, writing nothing meanwhile, so age
// alone does not tell an abandoned one: one untouched for kStaleTemporary is removed only if no
// live writer holds its lock (remove_abandoned_temp); by age alone, a second render opening
// the cache would remove a slow build's temporary, and the build fail at its end ("cannot
// write lattice table"). Failures are ignored: another run may race us.
void TableCache::remove_stale_temporaries() const {
    std::error_code ec;
    const auto now = std::filesystem::file_time_type::clock::now();
    for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.find(".lht.tmp-") == std::string::npos || !entry.is_regular_file(ec)) continue;
        const auto modified = entry.last_write_time(ec);
        if (!ec && now - modified > kStaleTemporary) remove_abandoned_temp(entry.path().string());
    }
}

std::string TableCache::path_for(const TablePlan& plan) const {
    const TableHeader& h = plan.header;
    std::string safe;
    for (char c : plan.primitive->name)
        safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
    char tail[64];
    std::snprintf(tail, sizeof tail, "-s%d-%s-%016llx.lht", h.sigma_inv, h.encoding.c_str(),
                  static_cast<unsigned long long>(h.fingerprint));
    return dir_ + "/" + safe.substr(0, 64) + tail;
}

bool TableCache::cached(const TablePlan& plan) const {
    const std::string path = path_for(plan);
    struct stat st {};
    const auto present = [&] { return ::stat(path.c_str(), &st) == 0; };
    return across_ranks_ ? dist::root_says(present) : present();
}

TableCache::Entry TableCache::get(const TablePlan& plan, bool progress) const {
    Entry e;
    e.path = path_for(plan);
    if (!cached(plan)) {
        const auto t0 = std::chrono::steady_clock::now();
        build_table_file(plan, e.path, progress, across_ranks_);
        e.build_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        e.built = true;
    }
    if (across_ranks_) dist::agree([&] { load(plan, e); });
    else load(plan, e);
    return e;
}

void TableCache::load(const TablePlan& plan, Entry& e) const {
    try {
        LoadedTable lt = load_table_file(e.path, &plan.header, plan.context.primitive);
        e.table = lt.table;
        e.header = lt.header;
        e.bytes = lt.bytes;
    } catch (const InputError& err) {
        if (across_ranks_ && !dist::is_root() && ::access(e.path.c_str(), F_OK) != 0)
            throw InputError(std::string(err.what()) +
                             " (rank 0 has it: the lattice cache directory must be one that every "
                             "rank shares, see --lattice-dir)");
        throw InputError(std::string(err.what()) + " (delete the file to rebuild it)");
    }
}

}  // namespace lat
