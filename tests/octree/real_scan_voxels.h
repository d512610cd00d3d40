// The voxel lists of real scans as the mapping engine's CPU back end shoots them: the input
// that the octree-stage tests (real data, decay, eviction) apply to OctoMap's tree and to ours.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/voxel_update.h"

namespace ort::test {

// The first max_scans scans of a graph file in ../shared/data (test::data_file's lookup) at
// 0.1 m, one VoxelList per scan; empty when the data set is not there (the caller skips).
std::vector<VoxelList> shoot_real_scans(const std::string& graph, size_t max_scans);

}  // namespace ort::test
