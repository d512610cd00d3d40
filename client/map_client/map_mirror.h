// A local OcTree kept equal to the server's map: one snapshot, then every delta applied in
// order (docs/PROTOCOL.md "Mirror"). A missed delta (a gap in delta_seq, or a change set
// whose start was not seen) makes it fetch a fresh snapshot and continue from there, with
// the deltas that arrived meanwhile; `on_delta` is called after each applied delta. A lost
// last delta (no later one shows the gap) is found by map_info_t (1 Hz), which names the last
// delta_seq sent: one never received is a gap too.
//
// Map state ids compare only within one epoch (docs/PROTOCOL.md "Ids"): a delta or map_info_t
// of another epoch than the mirror's snapshot (a reset, a server that lost changes in a crash,
// another map file) makes it resync. A server restarted cleanly keeps epoch and id and starts
// its delta_seq again: a change set that starts exactly at the mirror's complete version is
// applied on (the version chain shows nothing was missed), so such a mirror goes on without a
// snapshot.
//
// In class mode (the server's default) the mirror's voxels have the right class (free /
// occupied / unknown), with the clamping bound as log-odds; in exact mode (server flag
// --delta-exact) they have the server's log-odds.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <octomap/OcTree.h>

#include "map_client/map_client.h"

namespace ort::client {

struct AppliedDelta {
  int64_t delta_seq = 0, to_version = 0;
  int32_t voxels = 0;
  bool set_complete = false;  // the mirror is now at to_version
  int64_t bytes = 0;          // encoded size of the message
};

struct MirrorOptions {
  bool resync = true;  // false: a gap is only counted (tests show what resync buys)
  int8_t snapshot_format = octomap_rt::map_chunk_t::FORMAT_OCTOMAP_FULL;
  double fetch_timeout_s = 30;
  std::function<void(const AppliedDelta&)> on_delta;
  // Called with every map_info_t heard (1 Hz), before the mirror checks it: a shard set's mirror
  // (shard_client/shard_mirror.h) checks the set each shard announces and when it last spoke.
  std::function<void(const octomap_rt::map_info_t&)> on_info;
};

struct MirrorStats {
  int64_t snapshots = 0, deltas_applied = 0, deltas_skipped = 0, gaps = 0, bad_deltas = 0, delta_bytes = 0;
  int64_t voxels_applied = 0;
  int64_t epoch_changes = 0;  // deltas or infos of another epoch seen (each a gap too)
};

class MapMirror {
 public:
  MapMirror(MapClient& client, MirrorOptions opts = {});
  // Fetches a fresh snapshot and applies the deltas that arrived meanwhile. Throws FetchError.
  void sync();
  // Handles deltas for `seconds`; resyncs (when enabled) on a gap.
  void spin(double seconds);

  bool synced() const { return tree_ != nullptr; }  // a snapshot was fetched
  const octomap::OcTree& tree() const { return *tree_; }
  int64_t version() const { return version_; }  // map state id the mirror is at
  int64_t epoch() const { return epoch_; }      // and its epoch
  const MirrorStats& stats() const { return stats_; }

 private:
  void on_delta(const octomap_rt::map_delta_t& d);
  void on_info(const octomap_rt::map_info_t& info);
  void process(const octomap_rt::map_delta_t& d, bool buffered);
  void apply(const octomap_rt::map_delta_t& d);
  void gap();

  MapClient& client_;
  MirrorOptions opts_;
  std::unique_ptr<octomap::OcTree> tree_;
  int64_t version_ = -1;
  int64_t epoch_ = 0;
  bool set_open_ = false;         // a change set's first parts applied, not yet its last
  int64_t last_seq_ = -1;         // last delta applied or skipped as contained
  int64_t highest_seq_ = -1;      // highest delta_seq received, or known to be in the snapshot
  int64_t latest_info_seq_ = -1;  // delta_seq of the latest map_info_t
  bool info_seen_ = false;
  bool started_ = false;  // a change set was applied from its first part since the snapshot
  bool syncing_ = false, need_sync_ = false;
  std::vector<octomap_rt::map_delta_t> buffered_;
  MirrorStats stats_;
};

}  // namespace ort::client
