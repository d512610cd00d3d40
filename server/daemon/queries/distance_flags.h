// The server's flags of distance queries (--distance-backend, --distance-threads,
// --distance-device), each checked at start, as engine/engine_flags does for the engine's.
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/queries/query_config.h"

namespace ort::daemon {

void add_distance_flags(CLI::App& app, DistanceServiceConfig& d);

}  // namespace ort::daemon
