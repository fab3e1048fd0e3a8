#pragma once
#include <string>

namespace lat {

// The whole file; throws InputError "path: cannot open <what>: reason" when it cannot.
std::string read_text_file(const std::string& path, const std::string& what = "file");

}  // namespace lat
