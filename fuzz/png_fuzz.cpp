// PNG files -> Image8 (read_png, which takes a path: the input goes through a file in the
// temporary directory). Every input must decode or throw InputError, quickly and without
// allocating more than the file can describe.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "io/image.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = (std::filesystem::temp_directory_path() /
                                     ("lattice-fuzz-png-" + std::to_string(::getpid()) + ".png"))
                                        .string();
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    const bool written = std::fwrite(data, 1, size, f) == size;
    std::fclose(f);
    if (!written) return 0;
    try {
        (void)lat::read_png(path);
    } catch (const lat::InputError&) {
    }
    return 0;
}
