// The server's map: the octree, the order its scans were applied in, and the lock that
// makes every reader (saves, status, snapshots, queries) see a state between two whole
// scans. Stage 2 holds the lock for one scan's octree update at a time.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <shared_mutex>
#include <string>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "daemon/map/applied_order.h"
#include "octree/leaf_changes.h"

namespace ort::daemon {

// Told of every applied scan, under the map lock, right after the tree changed: `changes`
// are the finest leaves the scan changed, with their values before and after (the octree
// stage's log, octree/leaf_changes.h; the observer may take it over, e.g. by a swap: the
// next update resets it), `version` the map state id it made. Keep it short: the pipeline's
// stage 2 waits.
class MapChangeObserver {
 public:
  virtual ~MapChangeObserver() = default;
  virtual void applied(LeafChanges& changes, const octomap::OcTree& tree, uint64_t version) = 0;
  // The map changed in a way not described by a voxel list (an edit, a reload): deltas
  // cannot carry it, so the observer makes clients resync. Also under the map lock.
  virtual void replaced(const octomap::OcTree& tree, uint64_t version) = 0;
};

class MapResidency;

struct MapState {
  // Writers (stage 2, edits) lock it exclusively; queries read under a shared lock.
  std::shared_mutex mutex;
  std::unique_ptr<octomap::OcTree> tree;
  AppliedOrder order;
  // The map state id: how many scans the map contains by its applied order, over the map's
  // whole life (a loaded map starts at its order file's count; +1 per applied scan, under
  // the lock). Two reads with the same version saw the same map. Snapshot ids and the map
  // state a query was answered on are this number. A map edit (daemon/map_edit_item.h)
  // also adds 1: the id changes whenever the map does.
  uint64_t version = 0;
  int64_t last_scan_utime = 0;            // utime of the newest applied scan
  octomap::point3d last_scan_origin;      // its sensor origin (where a clipped grid is centred)
  MapChangeObserver* observer = nullptr;  // set before the pipeline starts
  // The memory bound (daemon/map/map_residency.h); null without --max-map-memory. Set before
  // the pipeline starts; whoever reads or changes voxels touches their regions through it.
  MapResidency* residency = nullptr;
  // Where each robot's newest applied scan was taken from and when it was applied (the
  // daemon's steady clock): clearing by distance keeps what is near the robots seen lately
  // (daemon/map/map_upkeep.h). At most kMaxRobotsSeen entries (the stalest goes first).
  struct RobotSeen {
    octomap::point3d origin;
    std::chrono::steady_clock::time_point applied;
  };
  static constexpr size_t kMaxRobotsSeen = 256;
  std::map<std::string, RobotSeen> robots_seen;
  // Newest applied seq per robot (lower-case id), for queries that wait for their own scan.
  std::map<std::string, int64_t> applied_seq;
  // Notified (without the lock held) after every applied scan or edit.
  std::condition_variable_any changed;
};

}  // namespace ort::daemon
