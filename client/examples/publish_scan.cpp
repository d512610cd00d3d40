// A robot's producer in C++: the first scan of an OctoMap ScanGraph (a real one:
// octomap_share/scan_dat.graph) published as a scan_t the way an organised cloud comes from a
// driver, with NaN for no-returns (here every tenth point). The server drops and counts the NaN
// points ("non-finite" in its status) and applies the rest. README.md, "Connect your robot".
//     octomap-rt-publish-example SCAN.graph [LCM_URL] [ROBOT_ID]
#include <cctype>
#include <cmath>
#include <iostream>
#include <string>

#include <octomap/ScanGraph.h>
#include <lcm/lcm-cpp.hpp>

#include "core/clock.h"
#include "octomap_rt/scan_t.hpp"
#include "protocol/channels.h"

int main(int argc, char** argv) {
  if (argc < 2) return std::cerr << "usage: " << argv[0] << " SCAN.graph [LCM_URL] [ROBOT_ID]\n", 2;
  octomap::ScanGraph graph;
  if (!graph.readBinary(argv[1]) || graph.size() == 0) return std::cerr << "cannot read " << argv[1] << "\n", 1;
  const octomap::ScanNode& node = **graph.begin();  // points in the sensor frame, pose map <- sensor
  const std::string robot = argc > 3 ? argv[3] : "cpprobot";
  octomap_rt::scan_t m;
  m.utime = ort::now_utime();                                               // acquisition time [us]
  m.seq = 0;                                                                // +1 per scan of this robot
  for (int i = 0; i < 3; ++i) m.sensor_position[i] = node.pose.trans()(i);  // map frame [m]
  const octomath::Quaternion& q = node.pose.rot();                          // unit, w x y z
  m.sensor_orientation[0] = q.u(), m.sensor_orientation[1] = q.x(), m.sensor_orientation[2] = q.y(),
  m.sensor_orientation[3] = q.z();
  m.max_range = -1;  // <= 0: the server's --max-range applies
  m.points_frame = octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  for (size_t i = 0; i < node.scan->size(); ++i) {
    const octomap::point3d p = (*node.scan)[i];
    const bool no_return = i % 10 == 0;  // as an organised cloud marks a pixel without a return
    for (int k = 0; k < 3; ++k) m.xyz.push_back(no_return ? NAN : p(k));
  }
  m.num_xyz = static_cast<int32_t>(m.xyz.size());
  m.robot_id = robot;  // = the channel's suffix
  m.map_frame = "map";
  std::string channel = ort::protocol::kScanChannelPrefix + robot;
  for (char& c : channel) c = char(std::toupper(static_cast<unsigned char>(c)));
  lcm::LCM lc(argc > 2 ? argv[2] : "");
  if (!lc.good() || lc.publish(channel, &m) != 0) return std::cerr << "publish failed\n", 1;
  std::cout << "published " << m.num_xyz / 3 << " points as " << robot << "\n";
}
