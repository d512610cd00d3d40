// octomap-rt-server's command line (CLI11) and optional config file (--config FILE, TOML or
// INI with the long flag names as keys, e.g. `resolution = 0.1`, `save-interval = 30`).
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/server_config.h"
#include "daemon/shard_flags.h"
#include "engine/engine_flags.h"

namespace ort::daemon {

struct ServerFlags {
  ort::cli::EngineFlags engine;
  ServerConfig server;
  bool no_pipeline = false;
  bool no_read_replica = false;
  double queue_mib = 0;
  double octomap_raw_max_kib = 0;  // 0: automatic
  std::string ns;                  // --namespace; "": $OCTOMAP_RT_NAMESPACE, else none
  bool print_config = false;       // --print-config: the effective configuration on stdout, then exit
  uint64_t max_scan_work = EngineOptions{}.max_scan_walk_keys;
  ShardFlags shard;                         // --shard, --shard-box, --shard-region-depth
  const CLI::Option* resolution = nullptr;  // -r: given, or taken from the map file
};

void add_server_flags(CLI::App& app, ServerFlags& f);
// -r's default from the map file, --map, --prior, --move-corrupt-map-aside, --save-interval,
// --applied-log (after the engine's flags).
void add_map_file_flags(CLI::App& app, ServerFlags& f);
// --pointcloud-min/max-x/y/z (map frame), --sensor-min/max-x/y/z, --min-range.
void add_point_filter_flags(CLI::App& app, PointFilters& f);
// --grid-rate, --grid-z MIN:MAX, --grid-cell (the grid published on OCTOMAP_RT_GRID).
void add_grid_flags(CLI::App& app, GridPublishConfig& g);
// Validates and converts (after parsing); throws CLI::ValidationError with a clear message.
ServerConfig to_server_config(const ServerFlags& f);

// Parses the command line (and --config FILE, whose unknown keys are refused) into `f`: "" when
// the flags are good, else the message to print (an unknown key names the nearest valid one).
// Throws CLI::CallForHelp / CallForVersion like CLI::App::parse.
std::string parse_server_flags(CLI::App& app, int argc, const char* const* argv);
// The configuration as a --config file would give it, every key with its value (--print-config).
std::string effective_config(const CLI::App& app);
// The long option name nearest to `key` (edit distance), without its dashes.
std::string nearest_option(const CLI::App& app, const std::string& key);

}  // namespace ort::daemon
