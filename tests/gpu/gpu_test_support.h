// Shared by the GPU back-end tests: making a back end, the reference voxel states of a
// scan, and comparing voxel lists with a message that names the rays involved.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/ray_backend.h"
#include "core/ray_batch.h"
#include "core/voxel_update.h"

namespace ort::test {

// A `vulkan` back end on the automatically chosen device (or $OCTOMAP_RT_TEST_DEVICE).
std::unique_ptr<RayBackend> make_vulkan(double resolution, double max_range = -1.0, uint64_t grid_budget_bytes = 0);

// The scan's consistent voxel states by the CPU references, ray by ray: OctoMap's own
// computeRayKeys (octomap mode) or ort::exact_ray_keys (exact mode), the end voxel occupied
// for measured ends (coordToKeyChecked), occupied winning. Sorted by key.
VoxelList reference_states(const RayBatch& batch, Traversal mode);

// Sorts by key (x, y, z) so lists can be compared.
void sort_voxels(VoxelList& v);
// Same keys with the same states, in the same order.
bool same_voxels(const VoxelList& a, const VoxelList& b);

// "" when equal; else how they differ (first few keys, and which rays of the batch have
// each differing key in their reference set).
std::string diff_voxels(const VoxelList& got, const VoxelList& want, const RayBatch& batch, Traversal mode);

}  // namespace ort::test
