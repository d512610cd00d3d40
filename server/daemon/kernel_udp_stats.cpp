#include "daemon/kernel_udp_stats.h"

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace ort::daemon {

int64_t parse_udp_rcvbuf_errors(std::istream& in) {
  // Two lines start with "Udp:": the column names, then the values.
  std::string line;
  std::vector<std::string> names;
  while (std::getline(in, line)) {
    if (line.rfind("Udp:", 0) != 0) continue;
    std::istringstream ls(line.substr(4));
    std::vector<std::string> fields;
    for (std::string f; ls >> f;) fields.push_back(f);
    if (names.empty()) {
      names = fields;
      continue;
    }
    for (size_t i = 0; i < names.size() && i < fields.size(); ++i) {
      if (names[i] == "RcvbufErrors") return std::stoll(fields[i]);
    }
    return -1;
  }
  return -1;
}

int64_t read_udp_rcvbuf_errors() {
  std::ifstream in("/proc/net/snmp");
  if (!in) return -1;
  try {
    return parse_udp_rcvbuf_errors(in);
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace ort::daemon
