#include "util/atomic_file.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <utility>
#include <vector>

#include "util/error.h"
#include "util/interrupt.h"

namespace lat {
namespace {

std::mutex g_mutex;
std::set<std::string>& registry() {
    static std::set<std::string> paths;  // guarded by g_mutex
    return paths;
}

void register_temp(const std::string& p) {
    const std::lock_guard lock(g_mutex);
    registry().insert(p);
}

void unregister_temp(const std::string& p) {
    const std::lock_guard lock(g_mutex);
    registry().erase(p);
}

// The process umask, read without changing it (umask() would, racing other threads).
mode_t current_umask() {
    std::ifstream status("/proc/self/status");
    std::string key;
    while (status >> key) {
        if (key == "Umask:") {
            std::string octal;
            status >> octal;
            return static_cast<mode_t>(std::strtoul(octal.c_str(), nullptr, 8));
        }
        status.ignore(1 << 16, '\n');
    }
    return 022;
}

}  // namespace

void throw_write_error(const std::string& path, const std::string& reason,
                       const std::string& what) {
    throw InputError(located_message(
        path, "", "cannot write" + (what.empty() ? "" : " " + what) + ": " + reason));
}

void throw_write_errno(const std::string& path, int err, const std::string& what) {
    throw_write_error(path, std::strerror(err != 0 ? err : EIO), what);
}

AtomicFile::AtomicFile(std::string target, std::string what)
    : target_(std::move(target)), what_(std::move(what)) {
    if (target_.empty()) throw InputError("cannot write: empty output path");
    // rename() would replace an empty directory or a device node; refuse both up front.
    struct stat st {};
    if (::stat(target_.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) throw_write_errno(target_, EISDIR, what_);
        if (!S_ISREG(st.st_mode)) throw_write_error(target_, "not a regular file", what_);
    }
    std::vector<char> name(target_.begin(), target_.end());
    for (const char c : std::string(".tmp-XXXXXX")) name.push_back(c);
    name.push_back('\0');
    const int fd = ::mkostemp(name.data(), O_CLOEXEC);
    if (fd < 0) throw_write_errno(target_, errno, what_);
    temp_ = name.data();
    register_temp(temp_);
    // Held until the descriptor closes (commit, destruction or the process's death), so that
    // remove_abandoned_temp leaves a live writer's temporary alone. On a filesystem without
    // flock its own lock fails too, and old temporaries stay rather than risk a live one.
    (void)::flock(fd, LOCK_EX | LOCK_NB);
    // mkstemp creates 0600; the target should get the usual permissions.
    static const mode_t mask = current_umask();
    file_ = ::fchmod(fd, 0666 & ~mask) == 0 ? ::fdopen(fd, "wb") : nullptr;
    if (file_ == nullptr) {
        const int err = errno;
        ::close(fd);
        ::unlink(temp_.c_str());
        unregister_temp(temp_);
        throw_write_errno(target_, err, what_);
    }
}

AtomicFile::~AtomicFile() {
    if (file_ != nullptr) std::fclose(file_);
    if (!committed_) {
        ::unlink(temp_.c_str());
        unregister_temp(temp_);
    }
}

void AtomicFile::write(const void* data, std::size_t n) {
    throw_if_interrupted();
    if (n != 0 && std::fwrite(data, 1, n, file_) != n) throw_write_errno(target_, errno, what_);
}

void AtomicFile::write_at(std::uint64_t offset, const void* data, std::size_t n) {
    throw_if_interrupted();
    if (std::fflush(file_) != 0) throw_write_errno(target_, errno, what_);
    const auto* p = static_cast<const char*>(data);
    while (n != 0) {
        const ssize_t k = ::pwrite(::fileno(file_), p, n, static_cast<off_t>(offset));
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) throw_write_errno(target_, k < 0 ? errno : EIO, what_);
        p += k, n -= static_cast<std::size_t>(k), offset += static_cast<std::uint64_t>(k);
    }
}

void AtomicFile::commit() {
    throw_if_interrupted();
    if (std::fflush(file_) != 0) throw_write_errno(target_, errno, what_);
    std::FILE* f = std::exchange(file_, nullptr);
    if (std::fclose(f) != 0) throw_write_errno(target_, errno, what_);
    if (std::rename(temp_.c_str(), target_.c_str()) != 0) throw_write_errno(target_, errno, what_);
    committed_ = true;
    unregister_temp(temp_);
}

bool remove_abandoned_temp(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    const bool abandoned = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    const bool removed = abandoned && ::unlink(path.c_str()) == 0;
    ::close(fd);
    return removed;
}

void remove_temp_files() {
    const std::lock_guard lock(g_mutex);
    for (const std::string& p : registry()) ::unlink(p.c_str());
    registry().clear();
}

std::size_t temp_file_count() {
    const std::lock_guard lock(g_mutex);
    return registry().size();
}

}  // namespace lat
