#pragma once
// Every file a user names (scene, mesh, lattice table, PNG, cache entry) is opened through
// here. A path that is not a regular file (FIFO, device, socket, directory) is refused before
// anything can block on it or read without end, and a file larger than the caller's limit is
// refused before any of it is read.
#include <cstdint>
#include <string>

namespace lat {

// Scene files and other JSON: room for the largest arrays a scene may hold (10,000,000
// entries), and a bound on what reading one can cost.
constexpr std::uint64_t kMaxTextFileBytes = std::uint64_t{1} << 30;

// A regular file open for reading. Throws InputError "path: cannot open <what>: reason", or
// "path: <what> of N bytes is over the limit of M bytes".
class InputFile {
public:
    InputFile(const std::string& path, const std::string& what, std::uint64_t max_bytes);
    ~InputFile();
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    int fd() const { return fd_; }
    std::uint64_t size() const { return size_; }
    // Hands the descriptor over (the caller closes it).
    int release();
    // The whole file, or the rest of it (throws InputError when reading fails or the file has
    // grown beyond the limit).
    std::string read_all();
    // Up to n bytes into buf; 0 at the end of the file (throws as read_all).
    std::size_t read_some(char* buf, std::size_t n);

private:
    std::string path_, what_;
    std::uint64_t max_bytes_;
    std::uint64_t size_ = 0;
    std::uint64_t read_ = 0;  // bytes read so far
    int fd_ = -1;
};

// The whole file, through InputFile.
std::string read_text_file(const std::string& path, const std::string& what = "file",
                           std::uint64_t max_bytes = kMaxTextFileBytes);

}  // namespace lat
