#include <cstdio>
#include <fstream>

#include "commands.h"
#include "util/error.h"

namespace lat::cli {

std::unique_ptr<tbb::global_control> limit_threads(int n) {
    if (n <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 static_cast<std::size_t>(n));
}

void write_json_file(const std::string& path, const nlohmann::json& j) {
    const std::string tmp = path + ".tmp";
    {
        std::ofstream f(tmp);
        f << j.dump(2) << "\n";
        if (!f) {
            std::remove(tmp.c_str());
            throw InputError(path + ": cannot write");
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw InputError(path + ": cannot write");
    }
}

}  // namespace lat::cli
