// A set of posed scans: what `octomap-rt build`, `replay` and `bench` read, whether from an
// OctoMap ScanGraph file or from the built-in synthetic scenes.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <octomap/Pointcloud.h>
#include <octomap/octomap_types.h>

namespace ort {

struct PosedScan {
  octomap::pose6d pose;        // sensor -> map
  octomap::Pointcloud points;  // sensor frame
};

struct ScanSet {
  std::string name;
  std::vector<PosedScan> scans;
  size_t total_points() const;
};

// Reads an OctoMap ScanGraph (.graph, binary). Throws std::runtime_error with the reason
// (truncated and inconsistent files included: they are checked before OctoMap reads them).
ScanSet load_scan_graph(const std::string& path);
// The same on a whole file in memory; `name` is for messages.
ScanSet parse_scan_graph(std::string_view bytes, const std::string& name);
// Writes one (ScanGraph binary, no edges).
void save_scan_graph(const ScanSet& set, const std::string& path);

// World-frame points exactly as OctoMap makes them: Pointcloud::transform(pose).
octomap::Pointcloud world_points(const PosedScan& scan);
// Sensor origin in the map frame: the pose's translation, as OctoMap uses it.
inline octomap::point3d sensor_origin(const PosedScan& scan) { return scan.pose.trans(); }

}  // namespace ort
