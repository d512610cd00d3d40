// The LCM URL the server listens on. Default: host-local multicast (ttl=0, packets never
// leave the host) with a raised receive buffer, because on udpm a multi-MB scan is lost
// whole unless the burst of all its fragments fits in the socket buffer
// (../shared/notes/lcm-1.3.1.md §3.3). The kernel caps that buffer at net.core.rmem_max.
#pragma once

#include <cstdint>
#include <string>

namespace ort::daemon {

struct LcmUrlChoice {
  std::string url;
  std::string warning;  // non-empty: say it once at start-up (rmem_max too small, ...)
};

// `requested` if given, else $LCM_DEFAULT_URL, else the wire contract's kDefaultLcmUrl. For udpm URLs without a
// recv_buf_size, adds recv_buf_size = min(wanted, rmem_max). `rmem_max` < 0: read it from
// /proc/sys/net/core/rmem_max.
LcmUrlChoice choose_lcm_url(const std::string& requested, uint64_t wanted_recv_buf, int64_t rmem_max = -1);

// /proc/sys/net/core/rmem_max, or -1 when unreadable.
int64_t read_rmem_max();

}  // namespace ort::daemon
