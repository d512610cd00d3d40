// Stage 1 of a scan when the server's point filters are on (--pointcloud-min-z, --min-range,
// ...: point_filters.h): the points in the map frame and as sent, the filters applied,
// the kept points shot as a map-frame scan. Always prepared on the CPU (a device that prepares
// scans gets the filtered points); without filters the pipeline keeps its fast path.
#pragma once

#include <vector>

#include "daemon/pipeline/point_filters.h"
#include "engine/map_engine.h"
#include "octomap_rt/scan_t.hpp"

namespace ort::daemon {

// Buffers kept between scans (a large scan's points, three times, are not allocated anew).
struct FilterScratch {
  std::vector<octomap::point3d> world, sensor, kept;
};

// Shoots `msg` (validated) with `filters` into `out`; returns what the filters removed.
FilterCounts shoot_filtered(MapEngine& engine, const octomap_rt::scan_t& msg, const PointFilters& filters,
                            double max_range, FilterScratch& scratch, ShotScan& out);

}  // namespace ort::daemon
