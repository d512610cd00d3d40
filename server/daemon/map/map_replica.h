// The read replica: a second tree kept equal to the map of record, for the whole-map readers
// (snapshots, saves, the viewer publisher, status counts). Stage 2 hands it each scan's voxel
// list (moved, not copied) and each other change as a replayable step, under the map lock
// and in the map's order; the replica's own thread applies them with its own octree stage,
// the same code on the same input in the same order, so at every state id its tree equals
// the map of record's node for node (tests/server/map_replica_test.cpp compares the .ot
// bytes). Readers lock the replica's MapState, never the map of record's: however long a
// copy or a serialization takes, the octree stage does not wait for it (docs/ARCHITECTURE.md
// "Readers and the read replica").
//
// Memory: one more tree, plus the voxel lists and steps not applied yet, at most
// `max_pending_bytes`; past that, stage 2 waits for the replica (only while a reader holds
// the replica longer than it takes the producers to send that much).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "daemon/map/map_identity.h"
#include "daemon/map/map_state.h"
#include "octree/octree_update.h"

namespace ort::daemon {

struct ReplicaStats {
  uint64_t version = 0;  // the replica's map state id
  uint64_t pending_items = 0, pending_bytes = 0;
  uint64_t max_pending_bytes_seen = 0;
  double writer_waited_ms = 0;  // stage 2's total wait for room (the bound above)
  double apply_ms_total = 0;    // the replica thread's own update time
};

class MapReplica {
 public:
  // Starts from a copy of `map` (its tree, id, epoch, scans, per-robot seqs): call before the
  // pipeline runs, with nothing else changing the map.
  MapReplica(const MapState& map, const OctreeUpdateOptions& octree, uint64_t max_pending_bytes);
  ~MapReplica();
  MapReplica(const MapReplica&) = delete;
  MapReplica& operator=(const MapReplica&) = delete;

  // Under the map lock, after the map of record applied the scan of `robot_lower` (its entry
  // in map.newest_scan is set): the replica takes the voxel list over (`voxels` is left empty)
  // and the state the map is at now.
  void scan_applied(VoxelList& voxels, const MapState& map, const std::string& robot_lower);
  // Under the map lock, after the map of record applied `step`: the replica applies it too.
  void step_applied(MapStep step, const MapState& map);

  // The state readers read: lock its mutex (shared) to read tree, version, epoch, ...
  MapState& state() { return state_; }
  // Waits until the replica reached `version` (or stopped); false on the timeout.
  bool wait_for(uint64_t version, double timeout_s);
  ReplicaStats stats() const;
  void stop();

 private:
  struct Item {
    VoxelList voxels;  // a scan's, or
    MapStep step;      // another change
    uint64_t version = 0, epoch = 0, scans = 0;
    int64_t last_scan_utime = 0;
    std::string robot;  // a scan's producer (lower case) and its newest scan
    MapState::NewestScan newest;
    uint64_t bytes = 0;
  };
  void push(Item item);
  void run();

  MapState state_;
  OctreeStage stage_;
  uint64_t max_pending_bytes_;
  mutable std::mutex mutex_;  // the queue and the stats
  std::condition_variable work_, room_, progress_;
  std::deque<Item> queue_;
  bool stop_ = false;
  ReplicaStats stats_;
  std::thread thread_;
};

// What whole-map readers read: the replica when the map has one, caught up with the map of
// record as it was at the call (read-your-writes: a reader that saw id N there gets N or
// newer); else the map of record itself.
MapState& readable_map(MapState& map);

}  // namespace ort::daemon
