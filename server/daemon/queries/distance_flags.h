// The server's flags of distance queries (--distance-backend, --distance-threads,
// --distance-device), each checked at start, as engine/engine_flags does for the engine's, and
// where the EDT runs as --distance-backend chose (CPU threads or the Vulkan device, once at start).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "daemon/queries/query_config.h"
#include "distance/squared_edt.h"

namespace ort::daemon {

void add_distance_flags(CLI::App& app, DistanceServiceConfig& d);

struct DistanceBackend {
  distance::SquaredEdt edt;
  std::string name;  // "cpu (N threads)" or "vulkan (DEVICE)"
};

// cpu: CPU threads. vulkan: the device, or std::invalid_argument / Unsupported (the server does
// not start). auto: the device where it is a GPU (not a CPU implementation such as lavapipe),
// else CPU threads. Throws std::invalid_argument for another backend name.
// `device`: a Vulkan device (index or name substring), "" automatic; `threads`: CPU EDT workers.
DistanceBackend choose_distance_backend(const std::string& backend, const std::string& device, int threads);

}  // namespace ort::daemon
