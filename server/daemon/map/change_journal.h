// The occupancy class changes of the map's recent states, for a reader that keeps a dense copy
// of a part of the map (the distance field cache's grid, daemon/queries/distance_answers.h):
// from the copy's state and the journal it knows the voxels that changed class since, without
// walking the tree or comparing grids.
//
// Stage 2 records each applied scan's class changes (from the octree stage's log, under the
// map's exclusive lock, before the delta observer takes the log) as the state id the scan made.
// A state made by anything else (an edit, a reset, a decay, clearing or eviction step, a
// restore) has no entry, so a reader asking across it is told no and reads the map again; so
// are readers asking for states trimmed away (the journal holds at most `max_changes` voxels)
// or older than the first scan after arm(). A state id names the same map on the read replica
// and on the map of record (daemon/map/map_replica.h), so a reader of either may ask.
//
// Nothing is recorded until a reader arms it (a daemon nobody asks for distances pays nothing).
// Thread-safe: stage 2 appends while readers copy (one mutex, held for the copy only).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

#include "octree/leaf_changes.h"

namespace ort::daemon {

// One voxel's class after a change: its Morton code (octree/batched/morton_order.h) and
// kOccupiedBit when it is occupied now (else it is free: a scan leaves no voxel unknown).
struct ClassChange {
  static constexpr uint64_t kOccupiedBit = 1ull << 63;
  uint64_t code = 0;
  uint64_t morton() const { return code & ~kOccupiedBit; }
  bool occupied() const { return (code & kOccupiedBit) != 0; }
};

struct ChangeJournalStats {
  uint64_t scans = 0;     // scans recorded since armed
  uint64_t changes = 0;   // class changes recorded
  uint64_t trimmed = 0;   // states dropped for room
  uint64_t answered = 0;  // changes_between that could answer
  uint64_t refused = 0;   // ... that could not (a state not in the journal)
  double record_ms = 0;   // stage 2's time in applied() (classify, append, trim) since armed
  size_t held_changes = 0;
};

class ChangeJournal {
 public:
  explicit ChangeJournal(size_t max_changes = 2'000'000, size_t max_states = 100'000);
  void arm() { armed_.store(true, std::memory_order_relaxed); }
  bool armed() const { return armed_.load(std::memory_order_relaxed); }

  // Stage 2, right after a scan made state `version`: its voxels whose class changed
  // (OctoMap's isNodeOccupied: log-odds >= occupancy_thres_log; unknown before counts as a class).
  void applied(const LeafChanges& changes, float occupancy_thres_log, uint64_t version);

  // The changes that lead from state `from` to state `to`, in the order applied, appended to
  // `out`; false (out as it was) when a state in (from, to] is not in the journal, or the
  // changes number more than `max_out`.
  bool changes_between(uint64_t from, uint64_t to, size_t max_out, std::vector<ClassChange>& out);

  ChangeJournalStats stats() const;

 private:
  struct State {
    uint64_t version = 0;
    std::vector<ClassChange> changes;
  };
  const size_t max_changes_, max_states_;
  std::atomic<bool> armed_{false};
  mutable std::mutex mutex_;
  std::deque<State> states_;  // consecutive runs of versions, oldest first
  size_t held_ = 0;
  ChangeJournalStats stats_;
};

}  // namespace ort::daemon
