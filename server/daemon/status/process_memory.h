// The server's own resident set, for the status beside the map's counted memory: the two
// differ by everything else the process holds, and by the pages of freed nodes, which the
// daemon's jemalloc (server/allocator/) hands back only after its dirty-page decay delay.
#pragma once

#include <cstdint>

namespace ort::daemon {

// Bytes resident now (/proc/self/statm); -1 when it cannot be read.
int64_t resident_set_bytes();

}  // namespace ort::daemon
