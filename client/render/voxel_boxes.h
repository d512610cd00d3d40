// The leaves of an OcTree as axis-aligned boxes, clipped to a height range: what the
// rasterizer draws.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <octomap/OcTree.h>

namespace ort::render {

struct Box3 {
  std::array<double, 3> lo{}, hi{};
  void extend(const Box3& b);
  bool empty() const { return lo[0] > hi[0]; }
  static Box3 none();  // the empty box: extend() with anything gives that thing
};

struct VoxelBox {
  std::array<float, 3> lo, hi;  // metres, already clipped to the height range
};

struct HeightRange {
  std::optional<double> min, max;  // unset: no limit
};

struct MapBoxes {
  std::vector<VoxelBox> occupied;
  std::vector<VoxelBox> free;
  Box3 occupied_bounds = Box3::none();
  Box3 free_bounds = Box3::none();
  double resolution = 0;
};

// Every leaf (pruned leaves as their larger boxes) that overlaps `range`, cut to it. Free
// leaves are collected only when `with_free` is set.
MapBoxes collect_boxes(const octomap::OcTree& tree, const HeightRange& range, bool with_free);

}  // namespace ort::render
