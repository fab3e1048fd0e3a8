#include "util/file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "util/error.h"

namespace lat {
namespace {

std::string kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "it is a directory";
    if (S_ISFIFO(mode)) return "it is a FIFO, not a regular file";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "it is a device, not a regular file";
    if (S_ISSOCK(mode)) return "it is a socket, not a regular file";
    return "not a regular file";
}

}  // namespace

// stat() first, so that a FIFO is refused without opening it (open() on a FIFO waits for a
// writer). The path may change between stat() and open(), so the descriptor is opened
// non-blocking and checked again with fstat().
InputFile::InputFile(const std::string& path, const std::string& what, std::uint64_t max_bytes)
    : path_(path), what_(what), max_bytes_(max_bytes) {
    auto refuse = [&](const std::string& why) {
        throw InputError(path + ": cannot open " + what + ": " + why);
    };
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) refuse(std::strerror(errno));
    if (!S_ISREG(st.st_mode)) refuse(kind_of(st.st_mode));
    fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0) refuse(std::strerror(errno));
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
        const std::string why = kind_of(st.st_mode);
        ::close(fd_);
        fd_ = -1;
        refuse(why);
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
    if (size_ > max_bytes) {
        ::close(fd_);
        fd_ = -1;
        throw InputError(path + ": " + what + " of " + std::to_string(size_) +
                         " bytes is over the limit of " + std::to_string(max_bytes) + " bytes");
    }
}

InputFile::~InputFile() {
    if (fd_ >= 0) ::close(fd_);
}

int InputFile::release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
}

// Reads to the end rather than trusting the size: a file may grow while it is read, and files
// under /proc say 0. Either way no more than the limit is taken.
std::size_t InputFile::read_some(char* buf, std::size_t n) {
    for (;;) {
        const ssize_t got = ::read(fd_, buf, n);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) throw InputError(path_ + ": cannot read " + what_ + ": " + std::strerror(errno));
        read_ += static_cast<std::uint64_t>(got);
        if (read_ > max_bytes_)
            throw InputError(path_ + ": " + what_ + " grew beyond the limit of " +
                             std::to_string(max_bytes_) + " bytes while it was read");
        return static_cast<std::size_t>(got);
    }
}

std::string InputFile::read_all() {
    std::string text;
    text.reserve(static_cast<std::size_t>(size_ > read_ ? size_ - read_ : 0));
    char buf[65536];
    while (const std::size_t n = read_some(buf, sizeof buf)) text.append(buf, n);
    return text;
}

std::string read_text_file(const std::string& path, const std::string& what,
                           std::uint64_t max_bytes) {
    InputFile f(path, what, max_bytes);
    return f.read_all();
}

}  // namespace lat
