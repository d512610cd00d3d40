// The voxel lists of real scans as the mapping engine's CPU back end shoots them: the input
// that the octree-stage tests (real data, decay, eviction) apply to OctoMap's tree and to ours.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <octomap/octomap_types.h>

#include "core/voxel_update.h"

namespace ort::test {

// Which points of one scan are shot, and as how many voxel lists: the point sets of a scan's
// world points seen from `origin` (each set one list, in order).
using ScanSplit = std::function<std::vector<std::vector<octomap::point3d>>(const std::vector<octomap::point3d>& world,
                                                                           const octomap::point3d& origin)>;

// The first max_scans scans of a graph file in ../shared/data (test::data_file's lookup) at
// 0.1 m, one VoxelList per scan (or per point set of `split`); empty when the data set is not
// there (the caller skips).
std::vector<VoxelList> shoot_real_scans(const std::string& graph, size_t max_scans, const ScanSplit& split = {});

}  // namespace ort::test
