// Live map deltas on OCTOMAP_RT_MAP_DELTA (map_delta_t, docs/PROTOCOL.md).
//
// As each scan is applied (under the map lock, MapChangeObserver), the octree stage has
// logged every finest leaf it changed with its value before and after
// (octree/leaf_changes.h). The publisher only takes that log over (a swap: nothing is
// looked up, classified or copied under the lock) and queues it. A thread of its own sends at
// most max_rate_hz change sets a second: the queued logs classified (class mode: unknown ->
// free/occupied, free <-> occupied; exact mode: every changed leaf with its log-odds;
// daemon/delta_changes.h), sorted, each key's newest value kept, delta-coded, compressed,
// cut into self-contained parts <= 60 KB, paced.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "core/log.h"
#include "core/threads/periodic_thread.h"
#include "daemon/map/map_state.h"
#include "daemon/transport/lcm_loop.h"
#include "octree/leaf_changes.h"
#include "protocol/channels.h"
#include "protocol/delta_codec.h"

namespace ort::daemon {

struct DeltaConfig {
  std::string channel = ort::protocol::kMapDeltaChannel;
  double max_rate_hz = 10;  // <= 0: no deltas
  bool exact = false;       // every changed leaf with its log-odds, not only class changes
  int zstd_level = 3;
  double part_interval_ms = 1.5;  // pacing between the parts of one change set
  std::string server_id;
  double resolution = 0;
};

struct DeltaStats {
  int64_t messages = 0, sets = 0, bytes = 0, voxels = 0, scans = 0;
  int64_t last_seq = -1;
};

class DeltaPublisher : public MapChangeObserver {
 public:
  DeltaPublisher(LcmLoop& loop, DeltaConfig cfg, std::function<int64_t()> latest_snapshot_id, Log log);
  ~DeltaPublisher() override;
  DeltaPublisher(const DeltaPublisher&) = delete;
  DeltaPublisher& operator=(const DeltaPublisher&) = delete;

  // `version`, `epoch`: the map's identity now (the first change set applies on it).
  void start(uint64_t version, uint64_t epoch);
  // Sends what is pending, then ends the thread. Idempotent.
  void stop();
  // Takes `changes` over and leaves it empty with some capacity (a used log given back).
  void applied(LeafChanges& changes, const octomap::OcTree& tree, uint64_t version) override;
  // Drops what is pending and skips one delta_seq on purpose: every mirror sees a gap and
  // resyncs from a snapshot at `version` or newer.
  void replaced(const octomap::OcTree& tree, uint64_t version, uint64_t epoch) override;
  DeltaStats stats() const;
  int64_t last_seq() const { return last_seq_; }

 private:
  void flush_or_log();  // the periodic task
  void flush();
  // Keeps a few of the sent logs for applied() to hand back to stage 2.
  void give_back(std::vector<LeafChanges>& logs);

  LcmLoop& loop_;
  DeltaConfig cfg_;
  std::function<int64_t()> latest_snapshot_id_;
  Log log_;

  mutable std::mutex mutex_;  // pending_, spare_, versions, stats_
  // The change logs of the scans applied since the last set, in the order applied: stage 2
  // only moves them in (it runs under the map lock); flush() classifies them.
  std::vector<LeafChanges> pending_;
  std::vector<LeafChanges> spare_;  // emptied logs, handed back to stage 2 to keep their capacity
  float occupancy_thres_log_ = 0;   // the map's, as of the newest pending scan
  uint64_t from_version_ = 0, to_version_ = 0, epoch_ = 0;
  int64_t pending_scans_ = 0;
  int64_t skip_seqs_ = 0;
  DeltaStats stats_;
  std::atomic<int64_t> last_seq_{-1};
  int64_t next_seq_ = 0;
  PeriodicThread periodic_;  // last: stopped before the members its task uses go
};

}  // namespace ort::daemon
