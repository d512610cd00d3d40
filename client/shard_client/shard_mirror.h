// Every shard's deltas followed in one mirror (docs/PROTOCOL.md, "Shards" and "Mirror"): one
// MapMirror per shard of the announced set, each on its shard's own namespace, so each keeps
// its shard's epoch, map state id and delta_seq chain and resyncs alone (a gap or a new epoch
// of shard 2 fetches shard 2's snapshot only). The one map is the shards' trees merged by
// map_client/shard_merge (disjoint regions: nothing to reconcile).
//
// The set is the one the shards' statuses announced (ShardRoster). Every shard's map_info_t
// (1 Hz) announces it again: an info of another set, or of another index than the shard's
// namespace says, is refused and counted, and does not count as hearing from that shard. A
// shard never fetched is missing; one that has sent no map_info_t for `late_after_s` is late.
// Both are said in words (shortfall()), and a merged map without every shard is partial.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "map_client/map_mirror.h"
#include "protocol/shards/shard_set.h"

namespace ort::client {

struct ShardMirrorOptions {
  MirrorOptions mirror;       // each shard's mirror (on_delta hears every shard's deltas)
  double late_after_s = 3.0;  // map_info_t comes at 1 Hz
  double retry_s = 3.0;       // a shard whose snapshot fetch failed is tried again after this
};

struct ShardMirrorPart {
  uint32_t index = 0;
  bool synced = false;              // holds a snapshot (and the deltas since)
  int64_t version = -1, epoch = 0;  // the map state id it is at, and its epoch
  MirrorStats stats;
  int64_t last_info_utime = 0;  // its last map_info_t of the right set (0: none yet)
  int64_t refused_infos = 0;    // map_info_t announcing another set or another index
  std::string error;            // the last snapshot fetch's failure ("" after a good one)
};

struct MergedMirror {
  std::unique_ptr<octomap::OcTree> tree;  // nullptr when no shard is synced
  std::vector<uint32_t> missing, late;    // shards without a snapshot; shards gone silent
  std::string shortfall;                  // both in words; "" when every shard is in and fresh
  bool partial() const { return !missing.empty(); }
};

class ShardMirror {
 public:
  // `set`: the announced set (a roster's, range-checked); `ns`: the namespace the shards share.
  ShardMirror(const std::string& url, const std::string& ns, const protocol::ShardSet& set,
              ShardMirrorOptions opts = {});
  ~ShardMirror();
  ShardMirror(const ShardMirror&) = delete;
  ShardMirror& operator=(const ShardMirror&) = delete;

  // Fetches the snapshot of every shard not synced yet; a shard that fails is missing (its
  // error kept), the others go on. Never throws for one shard's failure.
  void sync();
  // Handles every shard's deltas for `seconds`; resyncs a shard on its gap or new epoch.
  void spin(double seconds);

  const protocol::ShardSet& set() const { return set_; }
  std::vector<ShardMirrorPart> parts() const;
  const MapMirror& shard(uint32_t index) const;
  // Every shard of the set synced and none late at `now_utime`.
  bool complete(int64_t now_utime) const { return shortfall(now_utime).empty(); }
  // "shard 2 of 3 missing: <why>; shard 1 late (no map info for 4.2 s)"; "" when complete.
  std::string shortfall(int64_t now_utime) const;
  // The synced shards' trees merged into the one map (partial when a shard is missing).
  MergedMirror merged(int64_t now_utime) const;

 private:
  struct Shard;
  void try_sync(Shard& s);
  std::vector<uint32_t> missing() const;
  std::vector<uint32_t> late(int64_t now_utime) const;

  protocol::ShardSet set_;
  ShardMirrorOptions opts_;
  std::vector<std::unique_ptr<Shard>> shards_;
};

}  // namespace ort::client
