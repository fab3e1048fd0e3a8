#pragma once
// Paths the tests need, fixed at configure time (tests never read ../shared).
#include <string>

namespace lat::test {

inline std::string source_path(const std::string& rel) {
    return std::string(LATTICE_SOURCE_DIR) + "/" + rel;
}
inline std::string lattice_binary() { return LATTICE_BINARY; }

}  // namespace lat::test
