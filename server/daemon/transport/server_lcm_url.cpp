#include "daemon/transport/server_lcm_url.h"

#include <cstdlib>
#include <fstream>

#include "protocol/lcm_url.h"

namespace ort::daemon {

int64_t read_rmem_max() {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  int64_t v = -1;
  if (!(in >> v)) return -1;
  return v;
}

LcmUrlChoice choose_lcm_url(const std::string& requested, uint64_t wanted, int64_t rmem_max) {
  LcmUrlChoice c;
  c.url = requested;
  if (c.url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    c.url = env && *env ? env : ort::protocol::kDefaultLcmUrl;
  }
  if (c.url.rfind("udpm://", 0) != 0) return c;
  if (rmem_max < 0) rmem_max = read_rmem_max();

  uint64_t asked = wanted;
  const auto at = c.url.find("recv_buf_size=");
  if (at != std::string::npos) {
    asked = std::strtoull(c.url.c_str() + at + 14, nullptr, 10);
  } else {
    const uint64_t give = rmem_max > 0 ? std::min<uint64_t>(wanted, static_cast<uint64_t>(rmem_max)) : wanted;
    c.url += (c.url.find('?') == std::string::npos ? "?" : "&");
    c.url += "recv_buf_size=" + std::to_string(give);
  }
  if (rmem_max > 0 && static_cast<uint64_t>(rmem_max) < asked) {
    c.warning = "the kernel caps UDP receive buffers at net.core.rmem_max = " + std::to_string(rmem_max) +
                " bytes, below the " + std::to_string(asked) +
                " wanted. Multi-MB scans from several robots can then be lost whole (they show up as "
                "kernel_rcvbuf_errors and scans_missed in the status). Raise it on this host with:\n"
                "    sudo sysctl -w net.core.rmem_max=" +
                std::to_string(asked) +
                "\n  (persist it in /etc/sysctl.d/; inside a network namespace the host's value applies)";
  }
  return c;
}

}  // namespace ort::daemon
