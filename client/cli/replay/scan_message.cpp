#include "cli/replay/scan_message.h"

#include <cctype>

#include "protocol/ids.h"
#include "protocol/limits.h"

namespace ort::cli {

octomap_rt::scan_t make_scan_message(const PosedScan& scan, const ScanMessageFields& f) {
  octomap_rt::scan_t m;
  m.utime = f.utime;
  m.seq = f.seq;
  const octomath::Vector3& t = scan.pose.trans();
  const octomath::Quaternion& q = scan.pose.rot();
  for (int i = 0; i < 3; ++i) m.sensor_position[i] = t(i);
  m.sensor_orientation[0] = q.u();
  m.sensor_orientation[1] = q.x();
  m.sensor_orientation[2] = q.y();
  m.sensor_orientation[3] = q.z();
  m.max_range = f.max_range;
  const bool map_frame = f.frame == PointsFrame::kMap;
  m.points_frame = map_frame ? octomap_rt::scan_t::POINTS_IN_MAP_FRAME : octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  const octomap::Pointcloud world = map_frame ? world_points(scan) : octomap::Pointcloud();
  const octomap::Pointcloud& pts = map_frame ? world : scan.points;
  const size_t stride = f.stride > 0 ? f.stride : 1;
  m.xyz.reserve(3 * (pts.size() / stride + 1));
  for (size_t i = 0; i < pts.size(); i += stride) {
    m.xyz.push_back(pts[i].x());
    m.xyz.push_back(pts[i].y());
    m.xyz.push_back(pts[i].z());
  }
  m.num_xyz = static_cast<int32_t>(m.xyz.size());
  m.robot_id = f.robot_id;
  m.map_frame = "map";
  return m;
}

std::string scan_channel(const std::string& prefix, const std::string& robot_id) {
  std::string c = prefix;
  for (char ch : robot_id) c += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return c;
}

std::string check_robot_id(const std::string& robot_id) {
  if (protocol::valid_robot_id(robot_id)) return "";  // the server's rule (protocol/ids.h)
  if (robot_id.empty() || robot_id.size() > protocol::kMaxRobotIdLength)
    return "robot id must have 1 to " + std::to_string(protocol::kMaxRobotIdLength) + " characters";
  return "robot id may only hold letters, digits, '_' and '-': " + robot_id;
}

}  // namespace ort::cli
