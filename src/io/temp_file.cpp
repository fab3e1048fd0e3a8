#include "io/temp_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "util/error.h"

namespace lat::io_detail {

void throw_write_error(const std::string& path, const std::string& reason) {
    throw InputError(located_message(path, "", "cannot write: " + reason));
}

void throw_write_errno(const std::string& path, int err) {
    // A failed stdio call that left errno alone still failed; say so rather than "Success".
    throw_write_error(path, std::strerror(err != 0 ? err : EIO));
}

void require_nonempty(const std::string& path, int width, int height) {
    if (width <= 0 || height <= 0) {
        throw_write_error(
            path, "empty image (" + std::to_string(width) + "x" + std::to_string(height) + ")");
    }
}

TempFile::TempFile(std::string target) : target_(std::move(target)) {
    if (target_.empty()) throw InputError("cannot write: empty output path");
    // rename() would replace an empty directory or a device node; refuse both up front.
    struct stat st {};
    if (::stat(target_.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) throw_write_errno(target_, EISDIR);
        if (!S_ISREG(st.st_mode)) throw_write_error(target_, "not a regular file");
    }
    temp_ = target_ + ".tmp-" + std::to_string(::getpid());
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) throw_write_errno(target_, errno);
    file_ = ::fdopen(fd, "wb");
    if (file_ == nullptr) {
        const int err = errno;
        ::close(fd);
        ::unlink(temp_.c_str());
        throw_write_errno(target_, err);
    }
}

TempFile::~TempFile() {
    if (file_ != nullptr) std::fclose(file_);
    if (!committed_) ::unlink(temp_.c_str());
}

void TempFile::write(const void* data, std::size_t n) {
    if (n != 0 && std::fwrite(data, 1, n, file_) != n) throw_write_errno(target_, errno);
}

void TempFile::commit() {
    if (std::fflush(file_) != 0) throw_write_errno(target_, errno);
    std::FILE* f = std::exchange(file_, nullptr);
    if (std::fclose(f) != 0) throw_write_errno(target_, errno);
    if (std::rename(temp_.c_str(), target_.c_str()) != 0) throw_write_errno(target_, errno);
    committed_ = true;
}

}  // namespace lat::io_detail
