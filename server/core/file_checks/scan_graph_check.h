// Validation of an OctoMap ScanGraph file (.graph, ScanGraph::writeBinary) before OctoMap's
// reader sees it. OctoMap 1.9.7's reader trusts the counts: it reserves a vector for the
// header's scan count (2^31-1 scans: 16 GB), and Pointcloud::readBinary asserts (abort, exit
// 134) when a cloud's data ends early. The check walks the layout and compares every count
// with the bytes that remain, so a truncated or inconsistent file is refused with a message.
//
// Layout (native byte order, as OctoMap writes it):
//   uint32 scans; per scan: uint32 points, points x Vector3, pose6d, uint32 id;
//   uint32 edges; per edge: uint32 first id, uint32 second id, pose6d, double weight.
//   Vector3 = int32 3 + 3 doubles; Quaternion = int32 4 + 4 doubles; pose6d = Vector3 + Quaternion.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace ort {

struct ScanGraphCheck {
  bool ok = false;
  std::string error;  // why not (names the scan and byte offset)
  uint64_t scans = 0, points = 0, edges = 0;
};

// Checks a whole .graph file held in memory. Never throws on any input.
ScanGraphCheck check_scan_graph(std::string_view bytes);

}  // namespace ort
