#include "daemon/intake/stage_cost_model.h"

#include <cmath>

namespace ort::daemon {

size_t StageCostModel::shape_of(double mean_ray_voxels) {
  if (!(mean_ray_voxels >= 2)) return 0;  // NaN too
  const double k = std::floor(std::log2(mean_ray_voxels));
  return k >= double(kShapes - 1) ? kShapes - 1 : static_cast<size_t>(k);
}

StageCostPrediction StageCostModel::predict(double walk_voxels, double mean_ray_voxels) const {
  if (!(walk_voxels > 0)) return {};
  const size_t shape = shape_of(mean_ray_voxels);
  if (ms_per_voxel_[shape] > 0) return {walk_voxels * ms_per_voxel_[shape], true};
  for (size_t d = 1; d < kShapes; ++d) {  // the nearest learned shape, the shorter one first
    if (shape >= d && ms_per_voxel_[shape - d] > 0) return {walk_voxels * ms_per_voxel_[shape - d], false};
    if (shape + d < kShapes && ms_per_voxel_[shape + d] > 0) return {walk_voxels * ms_per_voxel_[shape + d], false};
  }
  return {};
}

double StageCostModel::longest_learned_ray_voxels() const {
  for (size_t k = kShapes; k-- > 0;)
    if (ms_per_voxel_[k] > 0) return std::ldexp(1.0, static_cast<int>(k) + 1);
  return 0;
}

void StageCostModel::learn(double walk_voxels, double mean_ray_voxels, double ms) {
  if (!(walk_voxels >= 1) || !(ms > 0) || !std::isfinite(ms)) return;
  double& rate = ms_per_voxel_[shape_of(mean_ray_voxels)];
  const double seen = ms / walk_voxels;
  // Half the last scan, half the ones before: follows the machine's load within a few scans.
  rate = rate > 0 ? 0.5 * rate + 0.5 * seen : seen;
}

}  // namespace ort::daemon
