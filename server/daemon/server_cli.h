// octomap-rt-server's command line (CLI11) and optional config file (--config FILE, TOML or
// INI with the long flag names as keys, e.g. `resolution = 0.1`, `save-interval = 30`).
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/server_config.h"
#include "engine/engine_flags.h"

namespace ort::daemon {

struct ServerFlags {
  ort::cli::EngineFlags engine;
  ServerConfig server;
  bool no_pipeline = false;
  double queue_mib = 0;
  double octomap_raw_max_kib = 0;  // 0: automatic
  uint64_t max_scan_work = EngineOptions{}.max_scan_walk_keys;
};

void add_server_flags(CLI::App& app, ServerFlags& f);
// --pointcloud-min/max-x/y/z (map frame), --sensor-min/max-x/y/z, --min-range.
void add_point_filter_flags(CLI::App& app, PointFilters& f);
// --grid-rate, --grid-z MIN:MAX, --grid-cell (the grid published on OCTOMAP_RT_GRID).
void add_grid_flags(CLI::App& app, GridPublishConfig& g);
// Validates and converts (after parsing); throws CLI::ValidationError with a clear message.
ServerConfig to_server_config(const ServerFlags& f);

}  // namespace ort::daemon
