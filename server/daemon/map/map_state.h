// The server's map: the octree, the order its scans were applied in, and the lock that
// makes every reader (saves, status, snapshots, queries) see a state between two whole
// scans. Stage 2 holds the lock for one scan's octree update at a time.
#pragma once

#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <shared_mutex>
#include <string>

#include <octomap/OcTree.h>

#include "core/clock.h"
#include "core/voxel_update.h"
#include "daemon/map/applied_order.h"
#include "daemon/map/map_lock_holders.h"
#include "daemon/map/map_mutex.h"
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
  // `epoch`: the map's epoch now (a reset starts a new one).
  virtual void replaced(const octomap::OcTree& tree, uint64_t version, uint64_t epoch) = 0;
};

class ChangeJournal;
class MapReplica;
class MapResidency;

// The key of a robot in the map's tables: its id in lower case (ids are case-insensitive).
inline std::string robot_key(std::string id) {
  for (char& c : id) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return id;
}

struct MapState {
  // Writers (stage 2, edits) lock it exclusively; queries read under a shared lock.
  MapMutex mutex;
  // Who held `mutex` and for how long (daemon/map/map_lock_holders.h): each holder names itself.
  MapLockHolders holders;
  std::unique_ptr<octomap::OcTree> tree;
  AppliedOrder order;
  // The map's identity (daemon/map/map_identity.h): `version` is the map state id, +1 for
  // every change (scan, edit, reset, loaded prior), under the lock, through
  // count_map_change/fork_map_history only; `epoch` names the history the id counts in and
  // changes when that history forks. Both are persisted with the map (a clean restart goes
  // on from them). Two reads with the same epoch and version saw the same map. Snapshot ids
  // and the map state a query was answered on are `version`.
  uint64_t version = 0;
  uint64_t epoch = 0;
  // The tree's leaf count (OctoMap's getNumLeafNodes()) kept without walking the tree: each
  // change through daemon/map/map_identity.h that knows how it changed the leaves adds that
  // (a scan through the batched octree stage, a reset); -1 after one that does not say (a
  // clear-box, a decay or clearing slice, an eviction or restore) until the status counts
  // the leaves again (daemon/status/map_figures.h). Changed under the exclusive lock, or by
  // that count under a shared lock (the status' calls are serialized): hence atomic.
  std::atomic<int64_t> leaves{-1};
  uint64_t scans = 0;                     // applied scans over the map's life (the applied order's length)
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
    SteadyClock::time_point applied;
  };
  static constexpr size_t kMaxRobotsSeen = 256;
  std::map<std::string, RobotSeen> robots_seen;
  // The read replica whole-map readers read (daemon/map/map_replica.h); null: they read this
  // map. Set before the pipeline starts; stage 2 feeds it every change.
  MapReplica* replica = nullptr;
  // The scans' occupancy class changes by state id (daemon/map/change_journal.h), for the
  // distance field cache's grid; null: none kept. Set before the pipeline starts.
  ChangeJournal* journal = nullptr;
  // Each robot's newest applied scan, by lower-case id: its seq (queries that wait for their
  // own scan), its id as sent and how many scans the map had applied with it (snapshots list
  // the producers with the most recent scans first).
  struct NewestScan {
    std::string robot_id;
    int64_t seq = -1;
    uint64_t scans = 0;
  };
  std::map<std::string, NewestScan> newest_scan;
  // Notified (without the lock held) after every applied scan or edit.
  std::condition_variable_any changed;
};

}  // namespace ort::daemon
