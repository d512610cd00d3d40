// The server's own resident set, for the status beside the map's counted memory: the two
// differ because glibc's malloc keeps freed nodes for reuse instead of handing their pages
// back (docs/ARCHITECTURE.md, "The memory bound").
#pragma once

#include <cstdint>

namespace ort::daemon {

// Bytes resident now (/proc/self/statm); -1 when it cannot be read.
int64_t resident_set_bytes();

}  // namespace ort::daemon
