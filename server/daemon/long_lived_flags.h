// octomap-rt-server's flags for a map that lives for weeks (issue 25): decay, clearing by
// distance, the regions they and the memory bound work on, and the memory bound itself
// (daemon/map/map_upkeep.h, daemon/map/map_residency.h).
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/server_config.h"

namespace ort::daemon {

void add_long_lived_flags(CLI::App& app, ServerConfig& c);

// Throws CLI::ValidationError naming the flag and why (validate_upkeep, memory_bound_problem).
void check_long_lived_flags(const ServerConfig& c);

}  // namespace ort::daemon
