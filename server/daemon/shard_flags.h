// octomap-rt-server's shard flags: --shard i/N picks shard i of N daemons that map one
// namespace's scans side by side (by the hash rule unless boxes are given), --shard-box gives
// the set's boxes in metres (one per shard, in shard order; they must tile the key space:
// overlaps and gaps are refused at start), --shard-region-depth the regions' depth.
// docs/PROTOCOL.md, "Shards".
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "daemon/server_config.h"
#include "protocol/shards/shard_set.h"

namespace ort::daemon {

struct ShardFlags {
  std::string shard;               // "i/N"; "": not sharded
  std::vector<std::string> boxes;  // "X0,Y0,Z0:X1,Y1,Z1" in metres, inf allowed
  unsigned region_depth = protocol::kDefaultShardRegionDepth;
};

void add_shard_flags(CLI::App& app, ShardFlags& f);

// The shard set the flags give (not sharded without --shard), the boxes' metres at `resolution`.
// Throws CLI::ValidationError saying why (an overlap or gap names the boxes and a point).
protocol::ShardSet to_shard_set(const ShardFlags& f, double resolution);

// A shard's own channels are those of protocol::shard_namespace(ns, index) (the caller applies
// it); this puts back what every shard shares, in namespace `ns`: the scan channels (every shard
// hears every scan) and the status (clients find the shards by their statuses). `given` holds
// the channel names as given by flag, before any namespace.
void keep_shared_channels(ServerConfig& c, const ServerConfig& given, const std::string& ns);

}  // namespace ort::daemon
