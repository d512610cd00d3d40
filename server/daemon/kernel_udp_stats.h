// The kernel's count of UDP datagrams dropped because a socket's receive buffer was full
// (/proc/net/snmp, "Udp:" RcvbufErrors; per network namespace). Nonzero growth while
// robots stream means lost scan fragments, i.e. lost scans.
#pragma once

#include <cstdint>
#include <istream>

namespace ort::daemon {

// -1 when unavailable.
int64_t read_udp_rcvbuf_errors();
int64_t parse_udp_rcvbuf_errors(std::istream& snmp);

}  // namespace ort::daemon
