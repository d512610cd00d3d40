// The snapshots a map service keeps: the last few, each in the formats asked for, so that a
// re-send of some chunks (or another client's request for the same state) does not copy or
// serialize the map again. Only the newest keeps its tree copy or its version of the read
// replica (to add the other format).
// Used by one thread (the map service's); the counters may be read from any.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>

#include "core/clock.h"
#include "daemon/map/map_replica.h"
#include "daemon/map/map_state.h"
#include "daemon/serving/snapshot_blob.h"

namespace ort::daemon {

struct SnapshotPolicy {
  size_t kept = 4;              // snapshots kept for re-sends
  int zstd_level = 3;           // 0: uncompressed
  double min_interval_s = 0.5;  // a new snapshot at most this often, however many ask
};

class SnapshotStore {
 public:
  explicit SnapshotStore(SnapshotPolicy policy) : policy_(policy) {}

  // The newest snapshot in `format`. A new one is copied from the map when the map changed
  // since the newest and that one is at least min_interval old (or there is none yet);
  // `took_new` says whether that happened.
  // With `fresh`, waits out min_interval instead, so the snapshot is at least as new as the
  // map was at the call.
  std::shared_ptr<const SnapshotBlob> latest(MapState& map, int8_t format, bool fresh, bool& took_new);
  // The newest kept snapshot in `format`, never a new copy; nullptr before the first.
  std::shared_ptr<const SnapshotBlob> newest(int8_t format) {
    return kept_.empty() ? nullptr : blob_of(kept_.back(), format);
  }
  // A kept snapshot by id, in `format` (made from the newest's copy if that is the one);
  // nullptr when no longer kept.
  std::shared_ptr<const SnapshotBlob> find(uint64_t id, int8_t format);
  // The blob last made (for map_info_t); nullptr before the first.
  std::shared_ptr<const SnapshotBlob> last_made() const { return last_made_; }

  int64_t latest_id() const { return latest_id_; }
  // When the newest snapshot was copied from the map ({} before the first).
  SteadyClock::time_point taken_at() const { return taken_at_; }
  int64_t taken() const { return taken_; }

 private:
  struct Entry {
    SnapshotContents contents;
    std::unique_ptr<octomap::OcTree> tree;          // newest only: a copy of the map of record, or
    std::shared_ptr<const ReplicaVersion> version;  // a version of the read replica (no copy)
    std::shared_ptr<const SnapshotBlob> blob[3];    // by format (1: .bt, 2: .ot)
  };
  std::shared_ptr<const SnapshotBlob> blob_of(Entry& e, int8_t format);
  void take(MapState& map);

  SnapshotPolicy policy_;
  std::deque<Entry> kept_;  // oldest first
  SteadyClock::time_point taken_at_;
  std::shared_ptr<const SnapshotBlob> last_made_;
  std::atomic<int64_t> latest_id_{-1}, taken_{0};
};

}  // namespace ort::daemon
