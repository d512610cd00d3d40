// Command-line flags shared by every subcommand that runs the engine (build, bench, the
// server): resolution, max range, back end, device, traversal, octree stage, sensor model.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "engine/map_engine.h"

namespace ort::cli {

struct EngineFlags {
  double resolution = 0.1;
  double max_range = -1.0;
  std::string backend = "auto";
  std::string device;
  std::string traversal = "octomap";
  std::string octree = "batched";
  unsigned threads = 0;
  SensorModel sensor;
};

// Accepted resolutions [m]: the key range (+-32768 voxels) spans 6.5 m to 65,000 km.
inline constexpr double kMinResolution = 1e-4;
inline constexpr double kMaxResolution = 1e3;

void add_engine_flags(CLI::App& cmd, EngineFlags& f, bool require_resolution);
// Validates and converts; throws CLI::ValidationError with a clear message.
EngineOptions to_engine_options(const EngineFlags& f);

}  // namespace ort::cli
