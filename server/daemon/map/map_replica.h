// The read replica: a second tree kept equal to the map of record, for the whole-map readers
// (snapshots, saves, the viewer publisher, status counts). Stage 2 hands it each scan's voxel
// list (moved, not copied) and each other change as a replayable step, under the map lock
// and in the map's order; the replica's own thread applies them with its own octree stage,
// the same code on the same input in the same order, so at every state id its tree equals
// the map of record's node for node (tests/server/map_replica_test.cpp compares the .ot
// bytes). Short readers (query turns, the status' figures) lock the replica's MapState.
// Whole-map readers (snapshots, saves, the viewer map) lock nothing: they take an immutable
// version of it (read_version), kept per region (octree/versions/map_version.h), that the replica's
// thread makes between two batches from its own tree, writing again only the cells where the
// batches since the last version changed a leaf (its octree stage's change log; the rest of a
// changed region copied from its old records); however long a reader holds or serializes its
// version, neither the octree stage nor the replica waits for it (docs/ARCHITECTURE.md
// "Readers and the read replica").
//
// Memory: one more tree; once a whole-map reader asked, the newest version (5 bytes a node)
// and what older versions readers still hold do not share with it (at most the regions
// changed since each); plus the voxel lists and steps not applied yet, at most
// `max_pending_bytes`; plus one buffer of at most `max_batch_voxels` voxels (8 bytes each),
// kept from batch to batch, and while versions are on the change log of a batch (16 bytes a
// changed leaf, at most one per voxel) and the changed cells since the last version (a
// 64-byte set per changed region); while it rebuilds (below), the tree it rebuilds (up to
// one more map) and the set of regions changed since their copy (8 bytes each, at most one
// per region of the map).
//
// Without rebuilds (`rebuild_slice_nodes` 0, the default), past `max_pending_bytes` stage 2
// waits for the replica's room, outside the map lock (wait_for_room).
//
// Falling behind (with rebuilds): stage 2 never waits for the replica. A change that finds the
// queue over `max_pending_bytes` (a reader held the replica, or its thread is slower than the
// producers)
// marks the replica fallen behind (counted, ReplicaStats::behind_reason says why): the queued
// lists are dropped, and from then on stage 2 only notes the regions (octree/region.h, depth
// kRebuildRegionDepth) its scans touch (a step: all of them). The replica's thread rebuilds
// a tree of its own from the map of record in slices (octree/versions/region_sync.h), each
// under a short shared lock of the map of record and at most `rebuild_slice_nodes` copied
// nodes, the regions changed since their copy copied again; the slice that finds none left
// to copy has made a tree equal to the map of record at its state then (no change can come
// in while it holds the lock), and hands it to the replica's thread as one change, as a
// scan's list is. Meanwhile readers read the replica's state as it was (a state between two
// whole scans, never changed by the rebuild) wherever that is new enough for them, else the
// map of record (readable_map, readable_version, lock_for_short_read), until it caught up.
//
// Keeping up: scans waiting back to back (a reader held the replica, or it fell behind) are
// applied as one list, their voxel lists one after the other. The batched octree stage applies
// a key repeated in a list in the list's order, as OctoMap's updateNode loop does
// (octree/batched/batched_update.h), so one update of the joined lists gives the tree that the
// scans give one by one; it costs less because each node on the scans' shared paths is walked
// and settled once, nodes pruned by one scan and expanded by the next are not, and the stage's
// fixed cost per update is paid once. The replica then goes from the state before the first
// to the state after the last (readers never see a state within a scan). With a time bound
// (`max_batch_ms`, ServerConfig::replica_batch_ms) a batch joins scans only while its estimated
// update time stays within it, so a catch-up is many short holds of the replica's lock, each
// about max(bound, one scan), instead of one long one; the scans stay whole. Its octree stage's
// helper threads run at nice 19 (octree/worker_pool.h): they take the cores the octree stage
// leaves idle, and yield them to it; the replica's own thread lowers its priority too (the
// server's: by 10), so that on a machine with few cores the octree stage goes first and the
// replica catches up, a batch at a time, when the stage waits for scans.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <thread>
#include <unordered_set>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "daemon/map/map_identity.h"
#include "daemon/map/map_state.h"
#include "octree/leaf_changes.h"
#include "octree/octree_update.h"
#include "octree/region.h"
#include "octree/versions/map_version.h"
#include "octree/worker_pool.h"

namespace ort::daemon {

// What a whole-map reader reads: an immutable version of the replica's tree (kept per region,
// octree/versions/map_version.h) at a state between two whole scans, with that state's identity.
struct ReplicaVersion {
  std::shared_ptr<const MapVersion> map;
  uint64_t version = 0, epoch = 0;
  size_t scans = 0;
  int64_t last_scan_utime = 0;
  std::map<std::string, MapState::NewestScan> newest_scan;
};

struct ReplicaStats {
  uint64_t version = 0;  // the replica's map state id
  uint64_t pending_items = 0, pending_bytes = 0;
  uint64_t max_pending_bytes_seen = 0;
  double writer_waited_ms = 0;  // stage 2's total wait for room (without rebuilds: the bound above)
  uint64_t writer_waits = 0;    // the times stage 2 began such a wait (a test sees it begin)
  uint64_t fell_behind = 0;     // the times a change found the queue over the bound (stage 2 goes on)
  uint64_t dropped_items = 0;   // the queued scans and steps those dropped
  std::string behind_reason;    // of the last time: the queue then, and the bound
  bool behind = false;          // rebuilding from the map of record now
  uint64_t rebuild_slices = 0, rebuild_regions_copied = 0, rebuild_nodes_copied = 0;
  uint64_t rebuilds_done = 0;                                 // rebuilds that caught up
  double rebuild_hold_ms_total = 0, rebuild_hold_ms_max = 0;  // its slices' hold of the map of record (shared)
  double apply_ms_total = 0;                                  // the replica thread's own update time (its lock held)
  double lock_wait_ms_total = 0;                              // the replica thread's wait for its lock (readers inside)
  double lock_wait_ms_max = 0;
  double idle_ms_total = 0;          // the replica thread's waits for work (the rest of its time: busy)
  double version_note_ms_total = 0;  // its time noting, after each batch, what the next version writes
  uint64_t updates = 0;              // tree updates it made: one per batch of scans or per step
  uint64_t scans_in_batches = 0;     // scans applied together with others
  uint64_t largest_batch = 0;        // most scans in one update
  uint64_t batches_cut_by_time = 0;  // batches that stopped joining scans at max_batch_ms (the estimate said so)
  double ms_per_voxel = 0;           // the estimate: of the replica's recent scan updates (0: none yet)
  uint64_t versions_built = 0;       // versions made for whole-map readers
  double version_ms_total = 0, version_ms_max = 0;            // the replica thread's time making them
  double version_ms_later = 0, version_cpu_ms_later = 0;      // of those after the first: wall, its CPU
  uint64_t version_regions = 0, version_regions_written = 0;  // of the last one
  uint64_t version_bytes = 0, version_bytes_written = 0;      // of the last one: its records, those written
  uint64_t version_bytes_written_later = 0;                   // by every version after the first
  uint64_t version_nodes_written_later = 0, version_nodes_copied_later = 0;  // of those: copied from old records
  unsigned version_depth = 0;                                                // of its regions
};

class MapReplica {
 public:
  // Starts from a copy of `map` (its tree, id, epoch, scans, per-robot seqs): call before the
  // pipeline runs, with nothing else changing the map. A rebuild reads `map` (its lock shared).
  // `max_batch_voxels` 0: one scan per update. `nice`: how much the replica's thread lowers
  // its priority below the server's (core/thread_priority.h; its octree stage's helpers:
  // octree.helper_nice).
  static constexpr uint64_t kDefaultBatchVoxels = uint64_t{1} << 23;
  // `version_grid`: the regions versions for whole-map readers are kept in; none: no versions
  // (whole-map readers copy the replica under its lock, the design before them: benchmarks
  // compare). `version_cells`: a version writes the cells the octree stage's change log names
  // (octree/versions/region_records.h); false: it rewrites the regions the scans' keys touched
  // whole (the design before, session 5).
  // `max_batch_ms` > 0: a batch joins scans only while the update's time, estimated from the ms
  // per voxel of the replica's recent scan updates, stays within it (no estimate yet: one scan),
  // so that the replica's lock is held about max(max_batch_ms, one scan) at a time and a query
  // turn that needs the replica waits behind no whole catch-up. 0: bounded by voxels only.
  // `rebuild_slice_nodes` > 0: past `max_pending_bytes` it falls behind and rebuilds, each slice
  // copying at most that many nodes (at least one region); 0: stage 2 waits for its room (the
  // rule before, and the default: on the H200 falling behind cost mapping far more, because
  // whole-map readers copy the map of record while it rebuilds: docs/BENCHMARKS.md, "Readers
  // and the read replica").
  static constexpr uint64_t kDefaultRebuildSliceNodes = 0;
  static constexpr unsigned kRebuildRegionDepth = 10;
  MapReplica(MapState& map, const OctreeUpdateOptions& octree, uint64_t max_pending_bytes,
             uint64_t max_batch_voxels = kDefaultBatchVoxels, int nice = 0,
             std::optional<RegionGrid> version_grid = region_grid(11), bool version_cells = true,
             double max_batch_ms = 0, uint64_t rebuild_slice_nodes = kDefaultRebuildSliceNodes);
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
  // Stage 2, before it takes the map lock for a scan of `voxels` voxels, without rebuilds:
  // waits until the queue has room for it (counted in writer_waited_ms), so that stage 2 waits
  // without holding the map of record and queries go on reading it. push keeps its own wait
  // for the rare case that another change took the room meanwhile. With rebuilds: returns.
  void wait_for_room(size_t voxels);
  // Waits until the replica reached `version` (or stopped, or fell behind); false on the timeout.
  bool wait_for(uint64_t version, double timeout_s);
  // The map of record's state id as of the last change handed over (stage 2 hands each over
  // under the map lock right after counting it), read without the map of record's lock;
  // and whether the replica has applied everything up to it (its tree is the map of record's).
  uint64_t record_version() const { return record_version_.load(std::memory_order_acquire); }
  bool caught_up() const {
    return applied_version_.load(std::memory_order_acquire) == record_version_.load(std::memory_order_acquire);
  }
  // A version at `min_version` or newer, for whole-map readers: the newest made when it is
  // new enough, else the replica's thread makes one as soon as it reached `min_version`
  // (between two batches, from its own tree: no lock a reader or the octree stage waits for).
  // The first call turns versions on (the replica's thread then notes the regions each batch
  // touches). The caller may hold it as long as it likes: the replica goes on.
  // After stop(), nullptr when the replica stopped behind the map of record.
  std::shared_ptr<const ReplicaVersion> read_version(uint64_t min_version);
  bool has_versions() const { return has_versions_; }
  ReplicaStats stats() const;
  // Ends its thread after the batch it is on; what is still queued is not applied (nothing
  // waits for a backlog at shutdown). Stage 2's waits for room end too.
  void stop();
  // Stopped with changes of the map of record not applied: readers read the map of record.
  bool stopped_behind() const;
  // Stopped behind, or fell behind and not caught up yet: whole-map readers read the map of record.
  bool reads_record() const;

 private:
  struct Item {
    VoxelList voxels;  // a scan's, or
    MapStep step;      // another change
    uint64_t version = 0, epoch = 0, scans = 0;
    int64_t last_scan_utime = 0;
    std::string robot;  // a scan's producer (lower case) and its newest scan
    MapState::NewestScan newest;
    uint64_t bytes = 0;
    // or a rebuilt tree that takes the replica's place, with the map's state then
    std::unique_ptr<octomap::OcTree> tree;
    std::map<std::string, MapState::NewestScan> newest_all;
    int64_t leaves = -1;
    bool whole() const { return step || tree; }  // never joined with scans in a batch
  };
  static uint64_t scan_bytes(size_t voxels) { return voxels * sizeof(VoxelUpdate) + sizeof(Item); }
  // Under mutex_ (`lock`), without rebuilds: waits while `bytes` more would pass the bound
  // (never for an empty queue).
  void wait_room_locked(std::unique_lock<std::mutex>& lock, uint64_t bytes);
  // Under mutex_, with rebuilds, when `item` finds the queue over the bound: drops the queue
  // and `item` (freed by the replica's thread), counts why, and marks every region to copy.
  void fall_behind_locked(Item item);
  // Under mutex_, while behind: notes the regions `item` changes (a step: all).
  void mark_dirty_locked(const Item& item);
  // One slice of the rebuild (map_replica_rebuild.cpp); returns how long it held the map of record (ms).
  double rebuild_slice();
  void push(Item item);
  void run();
  // Under mutex_: the front item, and the scans right behind a scan up to max_batch_voxels_
  // (and max_batch_ms_ as estimated).
  void take_batch(std::deque<Item>& batch);
  // Applies a batch to the tree and takes its last item's state (under state_.mutex), with
  // `log_changes` the leaves it changed in changes_. Returns how long it waited for that lock (ms).
  // A tree it replaced goes to `retired` (freed outside the lock).
  double apply_batch(std::deque<Item>& batch, bool log_changes, std::unique_ptr<octomap::OcTree>& retired);
  // Makes a version of the tree as the replica's thread left it (after its last batch, or
  // after it exited) and publishes it.
  void make_version();

  MapState state_;
  MapState& record_;  // the map of record, read by a rebuild
  OctreeStage stage_;
  uint64_t max_pending_bytes_;
  uint64_t max_batch_voxels_;
  double max_batch_ms_;
  double ms_per_voxel_ = 0;   // the replica's thread's estimate (only that thread reads or writes it)
  VoxelList joined_;          // a batch's voxel lists one after the other (capacity kept)
  LeafChanges changes_;       // the leaves a batch changed, while versions are on (capacity kept)
  mutable std::mutex mutex_;  // the queue and the stats
  std::condition_variable work_, room_, progress_;
  std::deque<Item> queue_;
  bool stop_ = false;
  ReplicaStats stats_;
  // Falling behind: set by push, cleared by the slice that caught up (under mutex_); the
  // regions changed since their copy, or all; the tree being rebuilt (the replica's thread
  // only); and a count of drops, so that a batch taken before one does not count its bytes
  // off the queue after it.
  bool behind_ = false, all_dirty_ = false;
  std::unordered_set<RegionId> dirty_;
  std::deque<Item> dropped_;  // freed by the replica's thread, not by stage 2 under the map lock
  uint64_t drops_ = 0;
  uint64_t rebuild_slice_nodes_;
  std::unique_ptr<octomap::OcTree> rebuild_tree_;
  std::atomic<uint64_t> record_version_{0}, applied_version_{0};
  // Versions: on after the first read_version; the newest made; the version a reader waits for.
  bool has_versions_, version_cells_;
  bool versions_on_ = false, exited_ = false;
  uint64_t wanted_version_ = 0;
  bool wanted_ = false;
  std::shared_ptr<const ReplicaVersion> latest_;
  std::mutex build_mutex_;  // the builder: the replica's thread, or a reader after it exited
  MapVersionBuilder builder_;
  // The threads that write a version's changed regions (made with the first version; its
  // helpers at the lowest priority, as the replica's octree stage's).
  unsigned version_threads_;
  std::unique_ptr<WorkerPool> version_pool_;
  std::thread thread_;
};

// What whole-map readers read: the replica when the map has one, caught up with the map of
// record as it was at the call (read-your-writes: a reader that saw id N there gets N or
// newer); else the map of record itself.
MapState& readable_map(MapState& map);
// The same for readers that serialize or copy the whole map: a version of the replica (read
// your writes as above) that neither the replica nor the octree stage waits for; null
// without a replica or without versions (the reader then copies readable_map's tree under
// its lock).
std::shared_ptr<const ReplicaVersion> readable_version(MapState& map);

// For short readers (a turn of queries): a shared lock on the map of record when stage 2 does
// not hold it; while it does, on the read replica if its thread is not writing it and it is at
// `min_version` or newer (a reader that passes the newest id it answered from never answers
// from an older state after a newer one). Both are states between two whole scans, each named
// by its own `version`. Returns the state locked, or null (`lock` empty) when neither is free
// for `min_version` now: it never waits, so that the caller can ask again with the readers
// waiting then (one that needs a newer state must not hold up those the replica can answer).
MapState* lock_for_short_read(MapState& map, uint64_t min_version, std::shared_lock<MapMutex>& lock);

}  // namespace ort::daemon
