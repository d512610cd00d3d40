// octomap-rt-server's bounds on what scans may cost over time (daemon/pipeline/scan_cost_gate.h;
// docs/RELIABILITY.md, "Bounded cost"): --max-origin-jump, --max-robot-speed, --max-scan-voxels,
// the new-node allowances per robot (--max-new-nodes-per-s, --new-node-burst) and for the map
// (--max-map-new-nodes-per-s, --map-new-node-burst), each range-checked at start.
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/pipeline/scan_cost_gate.h"

namespace ort::daemon {

void add_scan_cost_flags(CLI::App& app, ScanCostBounds& c);

}  // namespace ort::daemon
