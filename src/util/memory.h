#pragma once
#include <cstddef>
#include <string>

namespace lat {

// The process's peak resident set size so far, in bytes (getrusage).
std::size_t peak_rss_bytes();
// The process's CPU time so far, user + system, all threads, in seconds (getrusage): what
// a job costs whatever else the machine runs.
double cpu_seconds();
// Memory the system can give without swapping (MemAvailable), in bytes; 0 if unknown.
std::size_t available_memory_bytes();
// "1.5 GB", "812 MB", "12.0 kB"
std::string human_bytes(double bytes);

}  // namespace lat
