#pragma once
#include <cstddef>

namespace lat {

// The process's peak resident set size so far, in bytes (getrusage).
std::size_t peak_rss_bytes();

}  // namespace lat
