// The process's own memory, as the benchmarks report it beside the tree's.
#pragma once

#include <cstdint>

namespace ort::cli {

// Resident set now (/proc/self/statm), bytes.
uint64_t current_rss_bytes();
// Peak resident set of the process so far (getrusage), bytes.
uint64_t peak_rss_bytes();

}  // namespace ort::cli
