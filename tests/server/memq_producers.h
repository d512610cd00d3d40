// What the in-process server tests' producers share: the channel of a robot id, a producer's
// counts by channel and reason, and several robots' scans of the synthetic scene.
#pragma once

#include <cctype>
#include <map>
#include <string>
#include <vector>

#include "daemon/intake/producer_registry.h"
#include "protocol/channels.h"
#include "scene/scan_set.h"
#include "scene/synthetic_scene.h"

namespace ort::test {

inline std::string channel_of(const std::string& robot) {
  std::string c = ort::protocol::kScanChannelPrefix;
  for (char ch : robot) c += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return c;
}

inline int64_t reason_count(const daemon::ProducerStats& p, daemon::Reject r) {
  return p.rejects[static_cast<size_t>(r)];
}

inline const daemon::ProducerStats* producer_on(const std::vector<daemon::ProducerStats>& v,
                                                const std::string& channel) {
  for (const auto& p : v)
    if (p.channel == channel) return &p;
  return nullptr;
}

// Scans for several robots, thinned copies of the synthetic scene's scans (each robot sees
// other points of the same poses) so a test is quick yet overlapping.
inline std::map<std::string, std::vector<PosedScan>> robot_scans(int robots, int scans_each, int thin) {
  const ScanSet scene = make_synthetic_rooms();
  std::map<std::string, std::vector<PosedScan>> out;
  for (int r = 0; r < robots; ++r) {
    const std::string id = "robot" + std::to_string(r);
    for (int k = 0; k < scans_each; ++k) {
      const PosedScan& src = scene.scans[(r + 2 * k) % scene.scans.size()];
      PosedScan s;
      s.pose = src.pose;
      for (size_t i = (r + k) % thin; i < src.points.size(); i += thin) s.points.push_back(src.points[i]);
      out[id].push_back(std::move(s));
    }
  }
  return out;
}

}  // namespace ort::test
