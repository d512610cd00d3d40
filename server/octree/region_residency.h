// The memory bound's bookkeeping (issue 25): which regions are in memory, which were spilled
// (octree/region_codec.h) and when each was last touched. Past the bound, the regions least
// recently touched are spilled; touching a spilled region brings it back first.
//
// Why a touched region's seven siblings come back with it: a spilled region's stand-in is a
// childless node, so an update that prunes the parent (its eight children leaves of one
// value) could swallow a stand-in where the map without eviction keeps a subtree. With all
// eight children of a touched region's parent real, every prune an update makes is the one
// it makes without eviction (stand-ins sit only at the region depth, and a node above with a
// stand-in below it has children, so it is never pruned).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/region.h"
#include "octree/region_codec.h"
#include "octree/region_sweep.h"
#include "octree/region_tally.h"
#include "octree/residency/working_set_window.h"

namespace ort {

// Where spilled regions go (daemon/persistence/region_store.h on disk; tests keep them in
// memory). put() must hold the bytes durably before it returns, or throw. With background
// writes (RegionResidency::start_background_writes) put() runs on the writer's thread; the
// residency never calls two of these at once.
class RegionSpill {
 public:
  virtual ~RegionSpill() = default;
  virtual void put(RegionId id, std::span<const uint8_t> bytes) = 0;
  virtual std::vector<uint8_t> get(RegionId id) = 0;
  virtual void erase(RegionId id) = 0;
};

// Where the bound's time goes, summed over the run (milliseconds, steady clock): what the
// daemon reports to say which part of eviction and restore costs a scan its latency.
struct ResidencyCosts {
  double list_ms = 0;     // listing and ordering the candidate regions (a walk above the region depth)
  double encode_ms = 0;   // a region's subtree into bytes
  double put_ms = 0;      // the spill's put (the store's file write)
  double strip_ms = 0;    // freeing the spilled subtree's nodes (or detaching them, with set_free_later)
  double get_ms = 0;      // the spill's get on restore (the store's file read)
  double rebuild_ms = 0;  // decoding and rebuilding a restored subtree
  // With background writes: encode_ms and put_ms are the writer's (off the caller's thread);
  // size_ms is the caller's count of a region's nodes before it detaches them, and
  // write_wait_ms the time the caller waited for the writer (a full queue, a restore of a
  // region being written, a flush).
  double size_ms = 0, write_wait_ms = 0;
  uint64_t reattached = 0;  // restores of regions not yet written, or not yet let go: no store read
};

struct ResidencyStats {
  uint64_t evictions = 0, restores = 0;
  // Sweeps over spilled regions: steps owed (kept, applied on return), regions deleted unread.
  uint64_t steps_owed = 0, owed_now = 0, dropped = 0;
  uint64_t evicted_regions = 0, evicted_bytes = 0;  // now
  ResidencyCosts costs;
};

// What one enforce() did: the regions spilled and the tree memory they freed, counted as
// OctoMap's memoryUsage() counts it (a node each, a child array of 8 pointers per inner node).
struct EnforceResult {
  size_t regions = 0;
  size_t listed = 0;  // regions holding a subtree before the call (0 when nothing was spilled)
  uint64_t bytes_freed = 0;
};

// Applies `steps` in order to region `id` of `tree` (its subtree in place, at the region
// depth), then settles the nodes above it as a sweep does: the region and every node it left
// without children deleted, the others the max of their children, each pruned (never the root,
// nor a node with a child `stand_in` says is still a stand-in).
void apply_owed_steps(octomap::OcTree& tree, const RegionGrid& grid, RegionId id,
                      std::span<const std::shared_ptr<const RegionStep>> steps,
                      const std::function<bool(RegionId)>& stand_in);

class RegionResidency {
 public:
  RegionResidency(const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes);
  ~RegionResidency();
  RegionResidency(const RegionResidency&) = delete;
  RegionResidency& operator=(const RegionResidency&) = delete;

  // From now on enforce() only detaches a region's nodes (counting them) and a writer thread
  // encodes and puts them; until put() has returned and a later call of this object's let
  // them go, the region is pending: its nodes are kept, restoring it puts them back (no store
  // read), and spilled_bytes() encodes them. At most `max_pending_nodes` wait: past that,
  // enforce() waits for the writer on its way back to the bound, and below it ends the pass
  // instead (the room it would make is not needed yet). A put() that throws puts the region back at the next
  // enforce(), which then throws (nothing was lost).
  void start_background_writes(uint64_t max_pending_nodes);
  // Nodes detached and not yet let go (pending writes), for the caller's memory count.
  uint64_t pending_nodes() const;

  // The regions named are about to be read or changed: each becomes the most recently
  // touched, and each spilled one (with its parent's other children) is brought back.
  void touch(octomap::OcTree& tree, std::span<const RegionId> ids);
  // touch() for the regions of a voxel list's keys.
  void touch_voxels(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels);
  // Spills the least recently touched regions until the tree's memory (OctoMap's
  // memoryUsage()) is within the bound. Returns the regions spilled.
  size_t enforce(octomap::OcTree& tree);
  // The same from a known memory figure `bytes_now` down to `target` (a caller that keeps its
  // own count: memoryUsage() walks the whole tree), spilling at most `max_groups` sibling
  // groups (a caller that spreads eviction over several calls). A put() that throws leaves
  // that region in the tree and ends the call with the exception (nothing was lost).
  // `budget_ms` (> 0) ends the call between two groups once that much time has gone and the
  // memory is within the bound (at least one group goes): a caller that spreads the way from
  // the bound down to `target` over several calls.
  // `idle_only`: only sibling groups none of whose regions is in the working set go (a caller
  // that leaves the regions in use alone: spilling a region the next scans touch again only
  // moves it back and forth).
  EnforceResult enforce(octomap::OcTree& tree, uint64_t bytes_now, uint64_t target, size_t max_groups = SIZE_MAX,
                        double budget_ms = 0, bool idle_only = false);
  // The regions in use (octree/residency/working_set_window.h): touch() touches them, scans
  // feed its rate (working_set().scan()).
  WorkingSetWindow& working_set() { return working_set_; }
  const WorkingSetWindow& working_set() const { return working_set_; }
  // Replaces the window (its T, its clock); call before the first touch: the regions touched
  // until now count as never touched by the new one.
  void set_working_set(WorkingSetWindow w) { working_set_ = std::move(w); }
  // The bytes of spilled region `id` (the store's, or a pending region's encoded from its
  // kept nodes). Call while nothing changes the tree (any lock that keeps writers out).
  std::vector<uint8_t> spilled_bytes(RegionId id) const;
  // Waits until every pending region is in the store.
  void flush();
  // Brings one spilled region back without counting it as touched (a sweep visiting every
  // region must not make the whole map "recent"). No-op when it is not spilled.
  void bring_back(octomap::OcTree& tree, RegionId id) { restore(tree, id); }
  // Region `id` is in the spill already (`bytes` of it) and a stand-in in the tree: a map
  // loaded under the bound (octree/map_file_split.h). Not counted as an eviction.
  void adopt_spilled(RegionId id, uint64_t bytes);
  // The same with the region's bytes, which go to the spill first (throws when it refuses).
  void adopt_spilled(RegionId id, std::span<const uint8_t> bytes);
  // The spilled regions whose cubes meet the key box [lo, hi] (inclusive).
  std::vector<RegionId> spilled_in(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi) const;
  std::vector<RegionId> spilled_ids() const;
  // The tree no longer holds any spilled region (a reset): drops them from the spill (and
  // counts the whole tree as changed).
  void forget_all();
  // Where spilled regions' nodes go: with a hook, they are detached from the tree and handed
  // to it to be freed elsewhere (octree/region_codec.h detach_region); without, freed here.
  void set_free_later(std::function<void(DetachedSubtree)> free_later) { free_later_ = std::move(free_later); }
  // Brings every spilled region back (a whole-map save or snapshot without the bound).
  void restore_all(octomap::OcTree& tree);
  bool spilled(RegionId id) const { return spilled_.count(id) != 0; }
  // Sweeps over spilled regions (octree/region_sweep.h): a region owes at most kMaxOwed steps
  // (past that a sweep brings it back); owe() keeps `step` for it, applied after the steps
  // before it when the region comes back (any way: a touch, a sweep, restore_all, a refused
  // write), then the nodes above it are settled as the sweep would have settled them (values,
  // prune, nodes left empty deleted). drop(): the region's stand-in was deleted from the tree
  // (the sweep's step deletes all of it): its bytes and kept nodes go unread.
  static constexpr size_t kMaxOwed = 64;
  bool can_owe(RegionId id) const;
  void owe(RegionId id, std::shared_ptr<const RegionStep> step);
  void drop(RegionId id);
  // The hooks of a sweep over `sweep` regions (as coarse as this grid's or coarser) that
  // leaves spilled regions on disk (octree/region_sweep.h); the caller serializes the calls.
  SweepSpill sweep_hooks(const RegionGrid& sweep);
  // The steps region `id` owes, in order (a whole-map copy applies them: apply_owed_steps).
  std::vector<std::shared_ptr<const RegionStep>> owed_steps(RegionId id) const;
  // After a failed or finished background put: puts failed regions back, lets written ones'
  // nodes go (to the free_later hook). Throws the first failure's error after putting back.
  void collect_writes(octomap::OcTree& tree);
  // The tree's memory as OctoMap's memoryUsage() counts it, exactly, without walking every
  // node (octree/region_tally.h): touches, restores and evictions tell the tally what they
  // change; whoever else changes the tree (edits, sweeps) calls changed_box or changed_all.
  uint64_t memory(const octomap::OcTree& tree) { return tally_.memory(tree); }
  void changed_box(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi) { tally_.changed_box(lo, hi); }
  void changed_all() { tally_.changed_all(); }
  const RegionTally& tally() const { return tally_; }
  ResidencyStats stats() const;
  const RegionGrid& grid() const { return grid_; }

 private:
  void restore(octomap::OcTree& tree, RegionId id);
  // After region `id` was put back in the tree: its owed steps, then the nodes above settled.
  void apply_owed(octomap::OcTree& tree, RegionId id);
  void let_go(DetachedSubtree d);
  // Background writes: detaches region `id` for the writer; returns the tree memory it freed.
  // With the kept nodes full: waits for the writer, or (!may_wait) detaches nothing, returns 0.
  uint64_t detach_for_writer(octomap::OcTree& tree, RegionId id, bool may_wait);
  void write_loop();
  void stop_writer();

  // A region detached and not yet let go (background writes).
  struct Pending {
    enum class State { kQueued, kWriting, kWritten, kFailed };
    DetachedSubtree nodes;
    float root_log_odds = 0;
    State state = State::kQueued;
    uint64_t bytes = 0;
    std::string error;
  };

  RegionGrid grid_;
  RegionSpill& spill_;
  uint64_t max_bytes_;
  std::function<void(DetachedSubtree)> free_later_;
  uint64_t tick_ = 0;  // orders touches (the clock may read the same for several)
  std::unordered_map<RegionId, uint64_t> last_touch_;
  WorkingSetWindow working_set_;
  std::unordered_map<RegionId, uint64_t> spilled_;  // id -> bytes spilled
  std::unordered_map<RegionId, std::vector<std::shared_ptr<const RegionStep>>> owed_;
  uint64_t owed_now_ = 0;  // steps in owed_
  ResidencyStats stats_;
  RegionTally tally_;

  // Background writes: pending_ and queue_ (and the writer's costs) behind write_mutex_; the
  // writer reads a pending region's nodes without it (nothing else touches them then).
  bool background_ = false;
  uint64_t max_pending_nodes_ = 0, pending_nodes_ = 0;
  mutable std::mutex write_mutex_;
  mutable std::mutex spill_mutex_;  // every call into spill_ (the writer's puts and this thread's reads)
  std::condition_variable written_, wake_writer_;
  std::unordered_map<RegionId, Pending> pending_;
  std::deque<RegionId> queue_;
  size_t writes_done_ = 0;  // kWritten or kFailed entries in pending_
  double writer_encode_ms_ = 0, writer_put_ms_ = 0;
  bool stopping_ = false;
  std::thread writer_;
};

}  // namespace ort
