// octomap-rt-intake-bench: the daemon's host work on each scan message before the GPU sees
// it, timed in one process on the scans of a ScanGraph file, sent as the producers send them
// (sensor frame, scan_t encoded):
//   LCM thread:  LCM's generated scan_t::decode + a std::isfinite test per float (the daemon
//                before 2026-11-29) against validate_scan (wire checks, daemon/scan_decode's
//                decoding, content checks: what the daemon runs now);
//   stage 1:     the former copy of the message's floats into an octomap::Pointcloud (the
//                daemon now hands the message's floats to the engine as they are), and one
//                memcpy of them (what the upload into mapped memory costs at least).
//
//   octomap-rt-intake-bench skt02.graph --rounds 5
//
// Prints each part's median over every scan and round, in ms a scan.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/clock.h"
#include "daemon/intake/scan_to_map.h"
#include "daemon/intake/scan_validation.h"
#include "scene/scan_set.h"

namespace {

using namespace ort;

std::vector<uint8_t> encode_scan(const PosedScan& scan) {
  octomap_rt::scan_t m{};
  for (int i = 0; i < 3; ++i) m.sensor_position[i] = scan.pose.trans()(i);
  const octomath::Quaternion& q = scan.pose.rot();
  m.sensor_orientation[0] = q.u(), m.sensor_orientation[1] = q.x(), m.sensor_orientation[2] = q.y(),
  m.sensor_orientation[3] = q.z();
  m.max_range = -1;
  m.points_frame = octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  for (size_t i = 0; i < scan.points.size(); ++i)
    for (int a = 0; a < 3; ++a) m.xyz.push_back(scan.points[i](a));
  m.num_xyz = static_cast<int32_t>(m.xyz.size());
  m.robot_id = "bench0";
  m.map_frame = "map";
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "octomap-rt-intake-bench: the daemon's host work on a scan message (decode, checks, the points' copies)"};
  std::string graph;
  int rounds = 5;
  app.add_option("graph", graph, "ScanGraph file (e.g. from octomap-rt-scenegen)")->required();
  app.add_option("--rounds", rounds, "passes over the scans")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  const ScanSet set = load_scan_graph(graph);
  std::vector<std::vector<uint8_t>> messages;
  size_t points = 0;
  for (const PosedScan& s : set.scans) {
    messages.push_back(encode_scan(s));
    points += s.points.size();
  }
  daemon::ScanLimits limits;
  limits.max_points = std::max<size_t>(limits.max_points, points);
  std::vector<double> lcm_decode, ours, to_pointcloud, one_copy;
  std::vector<float> upload;
  int rejected = 0;
  for (int r = 0; r < rounds; ++r) {
    for (const auto& bytes : messages) {
      auto t = SteadyClock::now();
      {
        octomap_rt::scan_t m;
        m.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
        bool finite = true;
        for (float v : m.xyz) finite = finite && std::isfinite(v);
        rejected += !finite;
        lcm_decode.push_back(ms_since(t));
      }
      octomap_rt::scan_t m;
      t = SteadyClock::now();
      rejected += daemon::validate_scan(bytes.data(), bytes.size(), "bench0", limits, m) != daemon::Reject::kNone;
      ours.push_back(ms_since(t));
      t = SteadyClock::now();
      {
        const daemon::PosedMessageScan s = daemon::to_posed_scan(m);
        to_pointcloud.push_back(ms_since(t));
      }
      upload.resize(m.xyz.size());
      t = SteadyClock::now();
      std::memcpy(upload.data(), m.xyz.data(), m.xyz.size() * sizeof(float));
      one_copy.push_back(ms_since(t));
    }
  }
  std::printf("%zu scans (%.0f points a scan) x %d rounds; medians, ms a scan:\n", set.scans.size(),
              double(points) / double(std::max<size_t>(1, set.scans.size())), rounds);
  std::printf("  LCM thread: LCM decode + isfinite loop %.3f; validate_scan (now) %.3f\n", median(lcm_decode),
              median(ours));
  std::printf("  stage 1:    copy into a Pointcloud (before) %.3f; one memcpy of the floats %.3f\n",
              median(to_pointcloud), median(one_copy));
  if (rejected) std::printf("  %d messages refused (none expected)\n", rejected);
  return rejected ? 1 : 0;
}
