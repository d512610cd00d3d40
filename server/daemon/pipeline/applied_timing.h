// One applied scan's times: its two stages, where the rest of its end-to-end time went, and
// what it was (producer, size, what it added to the map). Stage 2 records one per scan.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "core/clock.h"
#include "core/ray_backend.h"

namespace ort::daemon {

// Where one scan's end-to-end time went besides the two stages: receipt -> decoded and
// queued (LCM thread) -> taken by stage 1 -> stage 1 done -> taken by stage 2.
struct ScanWaits {
  double decode_ms = 0;   // the LCM thread decoding and checking the message
  double queue_ms = 0;    // in the scan queue, behind scans that came before it
  double handoff_ms = 0;  // shot, waiting for stage 2 to finish the scan before it
};

// Stage 2's parts: octree_ms = lock_wait_ms + update_ms + publish_ms (and a few bookkeeping
// microseconds).
struct Stage2Parts {
  double lock_wait_ms = 0;       // waiting for the map lock (a snapshot copy, a status count, a query)
  double update_ms = 0;          // MapEngine::apply: the octree update (and its change log)
  double publish_ms = 0;         // the map observer (deltas, grid) on the scan's changes
  const char* lock_holder = "";  // who let go of the map lock last before stage 2 got it
};

struct AppliedTiming {
  double shoot_ms = 0;       // stage 1 wall time: to map frame + MapEngine::shoot
  double octree_ms = 0;      // stage 2 wall time: MapEngine::apply (map lock held)
  double end_to_end_ms = 0;  // receipt by the LCM thread -> applied
  int64_t points = 0;
  bool overlapped = false;  // its octree update overlapped a shoot of another scan
  ScanWaits waits;
  StageTimes stage1;  // the engine's parts of stage 1 (prepare, upload, shoot, compact)
  Stage2Parts stage2;
  std::string robot_id;
  int64_t seq = 0;
  SteadyClock::time_point received;  // by the LCM thread
  uint64_t voxels = 0;               // voxel updates stage 2 applied (free + occupied)
  int64_t new_nodes = 0;             // octree nodes the scan added (negative: pruned more than added)
};

}  // namespace ort::daemon
