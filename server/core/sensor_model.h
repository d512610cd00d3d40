// OctoMap's sensor model, explicit: hit/miss probabilities, clamping and the occupancy
// threshold. Defaults are OctoMap's own (OcTree's constructor).
#pragma once

#include <octomap/OcTree.h>

namespace ort {

struct SensorModel {
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamping_min = 0.1192;
  double clamping_max = 0.971;
  double occupancy_threshold = 0.5;
};

inline void apply_sensor_model(octomap::OcTree& tree, const SensorModel& m) {
  tree.setProbHit(m.prob_hit);
  tree.setProbMiss(m.prob_miss);
  tree.setClampingThresMin(m.clamping_min);
  tree.setClampingThresMax(m.clamping_max);
  tree.setOccupancyThres(m.occupancy_threshold);
}

}  // namespace ort
