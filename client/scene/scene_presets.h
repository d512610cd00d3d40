// Named scan-set presets at the scale of the paper's Table I, made in memory from a seed:
//
//   fr079         indoor building, spinning LiDAR: 66 scans of ~89K points (FR-079 corridor)
//   campus        outdoor campus, long-range LiDAR: 81 scans of ~247K points (Freiburg campus)
//   skt-corridor  indoor corridors, RGB-D 640x480, 0.3-8 m, two robots: 305 scans of ~270K
//                 points (Ewha-SKT B/D corridor)
//   fr079-real    OctoMap's real FR-079 map (geb079.bt, from the data folder) seen by the
//                 fr079 LiDAR along a path through its free space
//
// A scale factor shrinks scans and points for CI and for slow machines; the scans kept are
// spread over the whole trajectory, so a scaled set still covers the whole world.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scan_set.h"

namespace ort {

struct PresetOptions {
  double scan_scale = 1.0;   // share of the preset's scans (at least one scan)
  double point_scale = 1.0;  // share of the points per scan (the sensor's rows and columns shrink)
  uint64_t seed = 1;
  int robots = 0;        // 0: the preset's own number of robots
  unsigned threads = 0;  // generation threads; 0: all hardware threads
  std::string data_dir;  // where fr079-real finds octomap_share/geb079.bt
};

struct PresetInfo {
  std::string name;
  std::string description;
  int scans;               // at scale 1
  double points_per_scan;  // the paper's figure it aims at
};

const std::vector<PresetInfo>& preset_catalog();
bool is_preset(const std::string& name);

// Throws std::runtime_error for an unknown name, or when fr079-real's map is missing.
ScanSet make_preset(const std::string& name, const PresetOptions& opts);

// "tiny" and "ci" are names for small scales (0.02 and 0.05); otherwise a number in (0, 1].
// Throws std::invalid_argument for anything else.
double parse_scale(const std::string& s);

}  // namespace ort
