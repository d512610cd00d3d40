// Shared by `octomap-rt map` subcommands (map_command.cpp, map_watch.cpp).
#pragma once

#include <string>

namespace ort::cli {

struct MapArgs {
  std::string lcm_url;
  std::string ns;  // --namespace
  double timeout_s = 30;
  bool json = false, quiet = false;
  double seconds = 0;    // watch: 0 = until Ctrl-C
  std::string save;      // watch: .ot written at the end
  bool shards = false;   // get, watch: the namespace is a shard set: merge every shard's map
  bool partial = false;  // get --shards: write the merged map even when a shard is missing
};

// 0, or 3 when a watch of a shard set ends with a shard missing or late.
int run_map_watch(const MapArgs& a);
// 0 when both maps classify every finest voxel alike, else 1.
int run_map_diff(const std::string& a, const std::string& b);

}  // namespace ort::cli
