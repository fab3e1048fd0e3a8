#pragma once
// The one way files are written: into a temporary beside the target, renamed over it when
// complete, so a failed, concurrent or interrupted write never leaves a partial file under the
// real name. Temporaries have unique names (TARGET.tmp-XXXXXX, by mkstemp), so concurrent
// writers of one target never collide; the last rename wins. Live temporaries are registered,
// so that an interrupted process can remove them on its way out (see util/interrupt.h).
#include <cstdint>
#include <cstdio>
#include <string>

namespace lat {

// "path: cannot write[ what]: reason" as an InputError.
[[noreturn]] void throw_write_error(const std::string& path, const std::string& reason,
                                    const std::string& what = "");
// Same, with strerror(err) as the reason (EIO when err is 0: a failed call still failed).
[[noreturn]] void throw_write_errno(const std::string& path, int err, const std::string& what = "");

class AtomicFile {
public:
    // Creates the temporary (mode 0666 less umask, like the final file). `what` names the kind
    // of file in messages, e.g. "lattice table". Throws InputError naming the target if that
    // is impossible, or if the target is a directory or not a regular file.
    explicit AtomicFile(std::string target, std::string what = "");
    ~AtomicFile();  // closes and removes the temporary unless commit() succeeded
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    std::FILE* file() const { return file_; }
    const std::string& target() const { return target_; }
    const std::string& temp_path() const { return temp_; }

    // Writes n bytes; throws InputError naming the target on failure, Interrupted on a signal.
    void write(const void* data, std::size_t n);
    // Writes n bytes at a byte offset of the file (after what write() buffered), for files
    // written in pieces out of order; the same errors as write().
    void write_at(std::uint64_t offset, const void* data, std::size_t n);
    // Flushes, closes and renames into place (no fsync: this guards against partial files, not
    // power loss). Throws InputError on failure and Interrupted (leaving the target untouched)
    // if a signal arrived.
    void commit();

private:
    std::string target_, what_, temp_;
    std::FILE* file_ = nullptr;
    bool committed_ = false;
};

// Removes the temporary at `path` if no live writer holds it (each AtomicFile holds an
// exclusive flock on its temporary while it exists, released when its process dies); false
// if one does, or it could not be removed. A table build can leave its temporary untouched
// for many minutes while it computes, so age alone does not tell an abandoned one.
bool remove_abandoned_temp(const std::string& path);

// Removes every registered temporary that still exists; for the exit path of an interrupted
// process (the destructors do the same when the stack unwinds).
void remove_temp_files();
// Number of live temporaries, for tests.
std::size_t temp_file_count();

}  // namespace lat
