#include "util/error.h"

namespace lat {

std::string located_message(const std::string& file, const std::string& where,
                            const std::string& what) {
    std::string out;
    if (!file.empty()) out += file + ": ";
    if (!where.empty()) out += where + ": ";
    return out + what;
}

}  // namespace lat
