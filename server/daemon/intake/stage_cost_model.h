// What a scan will cost the stages, predicted before its turn (docs/RELIABILITY.md, "Share of
// the stages"): its walk (rays x their mean length in voxels, intake/scan_to_map.h's
// ray_lengths) times the stage time a walked voxel took in the scans of the same shape that
// the daemon applied before. Shape is the mean ray length's power of two: the time a voxel
// takes differs by orders of magnitude between a robot's short rays through mapped space and
// a few rays far out into unknown space (every voxel there a new node, one long walk a ray),
// so one rate for all would predict either wrong. The rates come from this daemon's own
// measurements (its back end, its machine, its load), from scans applied whole only: a
// refused scan teaches nothing. A shape never applied yet borrows the nearest learned shape's
// rate and is marked as a guess (the pipeline refuses on a learned prediction only).
#pragma once

#include <array>
#include <cstddef>

namespace ort::daemon {

struct StageCostPrediction {
  double ms = 0;         // both stages' time, predicted
  bool learned = false;  // from scans of this shape (false: borrowed, or nothing learned yet)
};

class StageCostModel {
 public:
  static constexpr size_t kShapes = 32;  // mean ray length 2^k .. 2^(k+1) voxels

  // Not thread-safe: the queue calls it under its mutex.
  StageCostPrediction predict(double walk_voxels, double mean_ray_voxels) const;
  // A scan of this walk and shape took `ms` of the stages, applied whole.
  void learn(double walk_voxels, double mean_ray_voxels, double ms);
  // The longest mean ray (in voxels: the upper end of its shape) of any shape learned; 0: none.
  // A scan whose rays are much longer walks into space no applied scan reached, where every
  // voxel is a new node: a borrowed rate says nothing about its cost.
  double longest_learned_ray_voxels() const;

 private:
  static size_t shape_of(double mean_ray_voxels);
  std::array<double, kShapes> ms_per_voxel_{};  // 0: not learned
};

}  // namespace ort::daemon
