#pragma once
// Internal to io/: the temporary file a writer fills before renaming it over the target, so a
// failed or interrupted write never leaves a partial image under the real name.
#include <cstdio>
#include <string>

namespace lat::io_detail {

// "path: cannot write: reason".
[[noreturn]] void throw_write_error(const std::string& path, const std::string& reason);
// Same, with strerror(err) as the reason.
[[noreturn]] void throw_write_errno(const std::string& path, int err);
// Image files cannot hold an empty image; throws InputError naming the path for one.
void require_nonempty(const std::string& path, int width, int height);

class TempFile {
  public:
    // Creates target + ".tmp-<pid>" (mode 0666 less umask, like the final file); throws
    // InputError naming the target if that is impossible.
    explicit TempFile(std::string target);
    ~TempFile();  // closes and removes the temporary unless commit() succeeded
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    std::FILE* file() const { return file_; }
    const std::string& target() const { return target_; }

    // Writes n bytes; on failure throws InputError naming the target.
    void write(const void* data, std::size_t n);
    // Flushes, closes and renames into place; throws InputError naming the target on failure.
    void commit();

  private:
    std::string target_, temp_;
    std::FILE* file_ = nullptr;
    bool committed_ = false;
};

}  // namespace lat::io_detail
