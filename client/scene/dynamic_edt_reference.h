// OctoMap's DynamicEDTOctomap (libdynamicedt3d-dev 1.9.7) over a block of voxels, the way the
// distance test and the distance bench compare octomap-rt's distances with it: it sees only the
// obstacles inside its bounding box, so it is given the block (our padded grid) with its corners
// at the block's outer voxel centres. Header-only: only programs that link DynamicEDT include it.
#pragma once

#include <dynamicEDT3D/dynamicEDTOctomap.h>
#include <octomap/OcTree.h>

#include <array>
#include <cstdint>
#include <memory>

namespace ort::scene {

// The centre of voxel (i, j, k) of the block whose first voxel has the keys `key_lo`.
inline octomap::point3d voxel_centre(const octomap::OcTree& tree, const std::array<int64_t, 3>& key_lo, int64_t i,
                                     int64_t j, int64_t k) {
  return octomap::point3d(float(tree.keyToCoord(octomap::key_type(key_lo[0] + i))),
                          float(tree.keyToCoord(octomap::key_type(key_lo[1] + j))),
                          float(tree.keyToCoord(octomap::key_type(key_lo[2] + k))));
}

// DynamicEDTOctomap over the block of `n` voxels from `key_lo`, updated. It turns on the
// tree's change detection (hence the non-const tree).
inline std::unique_ptr<DynamicEDTOctomap> dynamic_edt_over(octomap::OcTree& tree, const std::array<int64_t, 3>& key_lo,
                                                           const std::array<int64_t, 3>& n, double max_distance,
                                                           bool unknown_occupied) {
  const octomap::point3d bmin = voxel_centre(tree, key_lo, 0, 0, 0);
  const octomap::point3d bmax = voxel_centre(tree, key_lo, n[0] - 1, n[1] - 1, n[2] - 1);
  auto edt = std::make_unique<DynamicEDTOctomap>(float(max_distance), &tree, bmin, bmax, unknown_occupied);
  edt->update();
  return edt;
}

}  // namespace ort::scene
