// One map from a shard set: a fresh .ot snapshot from every shard heard (each on its own
// namespace's map protocol, fetched side by side), merged by client/map_client/shard_merge into
// the map one daemon would hold. What each shard contributed (its snapshot's map state id and
// scans, or why it is missing) is kept beside the map: a merged map without every shard is
// marked partial, never passed off as whole.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "shard_client/shard_roster.h"

namespace ort::client {

struct ShardPart {
  uint32_t index = 0;
  bool fetched = false;
  int64_t snapshot_id = 0, num_scans = 0;  // the shard's map state id and scans in its snapshot
  int64_t epoch = 0;                       // the history its snapshot id counts in
  int64_t bytes = 0;                       // its .ot
  double seconds = 0;
  std::string error;  // why it is missing
};

struct MergedMap {
  std::unique_ptr<octomap::OcTree> tree;  // nullptr when no shard could be fetched
  std::vector<ShardPart> parts;           // one per shard of the set, by index
  bool partial = false;                   // a shard is missing: the map lacks its regions
  std::string shortfall;                  // what is missing, said in words
};

// Fetches every shard of `roster`'s set in namespace `ns` and merges them (each fetch gets
// `timeout_s`). Throws std::runtime_error when the roster heard no shard.
MergedMap fetch_merged_map(const std::string& url, const std::string& ns, const ShardRoster& roster, double timeout_s);

}  // namespace ort::client
