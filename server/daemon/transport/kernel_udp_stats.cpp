#include "daemon/transport/kernel_udp_stats.h"

#include <filesystem>
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

int64_t parse_udp_socket_drops(std::istream& in, const std::set<uint64_t>& inodes) {
  // sl local rem st tx:rx tr:when retrnsmt uid timeout inode ref pointer drops
  std::string line;
  std::getline(in, line);  // header
  int64_t drops = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::vector<std::string> f;
    for (std::string x; ls >> x;) f.push_back(x);
    if (f.size() < 13) continue;
    if (inodes.count(std::stoull(f[9]))) drops += std::stoll(f[12]);
  }
  return drops;
}

int64_t read_own_udp_drops() {
  std::set<uint64_t> inodes;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd", ec)) {
    std::error_code ec2;
    const std::string target = std::filesystem::read_symlink(e.path(), ec2).string();
    if (!ec2 && target.rfind("socket:[", 0) == 0) inodes.insert(std::stoull(target.substr(8)));
  }
  if (ec) return -1;
  int64_t drops = 0;
  bool any = false;
  for (const char* path : {"/proc/self/net/udp", "/proc/self/net/udp6"}) {
    std::ifstream in(path);
    if (!in) continue;
    any = true;
    try {
      drops += parse_udp_socket_drops(in, inodes);
    } catch (const std::exception&) {
      return -1;
    }
  }
  return any ? drops : -1;
}

}  // namespace ort::daemon
