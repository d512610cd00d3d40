// Warming an engine up before it maps: one synthetic scan shot (stage 1) and applied to a
// scratch tree (stage 2) that is then thrown away. The first scan a fresh engine takes pays
// one-time costs: the device's ray and upload buffers grow to the scan's size, the driver's
// first submissions, the octree stage's threads and buffers made on first use (octree/
// octree_update.h: OctreeStage), the first touch of their pages. In a daemon the scans that
// arrive meanwhile queue behind it, so a p99 over a run that starts on a fresh daemon carries
// those costs several times (docs/history/benchmarks-log.md, "warm-up at start"). The map is untouched: the scan
// goes to a tree of its own, and the GPU grid is clear again after every shot.
#pragma once

#include <cstddef>

#include "engine/map_engine.h"

namespace ort {

struct WarmUpReport {
  size_t points = 0;
  uint64_t voxels = 0;  // the scratch tree's voxel updates
  double shoot_ms = 0, apply_ms = 0;
  bool refused = false;  // the engine refused the scan (origin, ray length, --max-scan-work)
};

// Shoots `points` points (0: does nothing) on a sphere of kWarmUpRadiusVoxels voxels' radius
// around the map origin, sensor frame = map frame, through the same path as a scan message's
// points (MapEngine::shoot_posed_xyz), then applies them to a fresh tree. The device buffers
// then fit scans of up to `points` points without growing, and the octree stage has run on
// about as many voxel updates as an RGB-D scan brings (the ball's ~270K keys). Call before any
// other thread uses the engine.
inline constexpr double kWarmUpRadiusVoxels = 40;
WarmUpReport warm_up(MapEngine& engine, size_t points);

}  // namespace ort
