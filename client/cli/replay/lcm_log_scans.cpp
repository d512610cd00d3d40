#include "cli/replay/lcm_log_scans.h"

#include <fstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

namespace ort::cli {

bool is_lcm_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {0, 0, 0, 0};
  if (!in.read(reinterpret_cast<char*>(magic), 4)) return false;
  return magic[0] == 0xED && magic[1] == 0xA1 && magic[2] == 0xDA && magic[3] == 0x01;
}

size_t for_each_log_scan(const std::string& path, const std::string& prefix,
                         const std::function<bool(const LogScanEvent&)>& fn) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot open LCM log " + path);
  size_t skipped = 0, index = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel.compare(0, prefix.size(), prefix) != 0) {
      ++skipped;
      continue;
    }
    LogScanEvent s;
    s.index = index++;
    s.timestamp = e->timestamp;
    s.channel = e->channel;
    s.data = e->data;
    s.size = static_cast<uint32_t>(e->datalen);
    if (!fn(s)) break;
  }
  return skipped;
}

}  // namespace ort::cli
