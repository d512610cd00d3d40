// The kernel's count of UDP datagrams dropped because a socket's receive buffer was full
// (/proc/net/snmp, "Udp:" RcvbufErrors; per network namespace). Nonzero growth while
// robots stream means lost scan fragments, i.e. lost scans.
#pragma once

#include <cstdint>
#include <istream>
#include <set>

namespace ort::daemon {

// -1 when unavailable.
int64_t read_udp_rcvbuf_errors();
int64_t parse_udp_rcvbuf_errors(std::istream& snmp);

// Datagrams dropped on THIS process's UDP sockets (the "drops" column of /proc/net/udp and
// udp6 for the socket inodes in /proc/self/fd). Unlike the namespace-wide RcvbufErrors it
// does not count other programs' sockets (each LCM udpm subscriber receives all traffic of
// its group and port, so a small-buffered client overflows without harming the server).
// -1 when unavailable.
int64_t read_own_udp_drops();
// Sum of drops over the lines of a /proc/net/udp file whose inode is in `inodes`.
int64_t parse_udp_socket_drops(std::istream& proc_net_udp, const std::set<uint64_t>& inodes);

}  // namespace ort::daemon
