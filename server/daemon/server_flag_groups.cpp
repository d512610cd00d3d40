// The groups of octomap-rt-server's flags that add_server_flags adds: the map file, the point
// filters, the published grid.
#include <stdexcept>
#include <string>

#include "daemon/server_cli.h"
#include "protocol/channels.h"

namespace ort::daemon {

void add_map_file_flags(CLI::App& app, ServerFlags& f) {
  ServerConfig& s = f.server;
  CLI::Option* resolution = app.get_option("--resolution");
  f.resolution = resolution;
  resolution->description(
      "voxel edge length [m]; default: the resolution of --map when it exists, else of --prior (one of them, or -r, "
      "is needed)");
  app.add_option("--map", s.map_path,
                 "the map of record (.ot, with log-odds): loaded at start if it exists, saved every --save-interval "
                 "seconds and at exit (atomically); the applied scan order goes to FILE.order, the map's identity to "
                 "FILE.identity; one server per file (FILE.lock)");
  app.add_option("--prior", s.prior_path,
                 "a map to start from (.bt or .ot, e.g. octomap_server's) when --map does not exist yet or is not "
                 "given; the new map is saved to --map, the prior file is never written");
  app.add_flag("--move-corrupt-map-aside", s.move_corrupt_map_aside,
               "when --map exists but is not a complete .ot file: rename it to FILE.corrupt-<UTC time> and start a "
               "new map (default: refuse to start)");
  app.add_option("--save-interval", s.save_interval_s, "seconds between periodic saves; 0: only at exit")
      ->capture_default_str();
  app.add_option("--applied-log", s.applied_log,
                 "also append each applied scan's (robot, seq) to this file as it happens");
}

void add_point_filter_flags(CLI::App& app, PointFilters& f) {
  // Each flag also answers to octomap_server's parameter name, so that a --config file may use
  // its keys (pointcloud_min_z = 0.1); README, "Connect your robot", has the table.
  const char* axes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const std::string a = axes[i];
    app.add_option(
        "--pointcloud-min-" + a + ",--pointcloud_min_" + a, f.map_frame.min[i],
        "drop points whose map-frame " + a + " is below this [m] (octomap_server's pointcloud_min_" + a + ")");
    app.add_option(
        "--pointcloud-max-" + a + ",--pointcloud_max_" + a, f.map_frame.max[i],
        "drop points whose map-frame " + a + " is above this [m] (octomap_server's pointcloud_max_" + a + ")");
    app.add_option("--sensor-min-" + a, f.sensor_frame.min[i],
                   "drop points whose " + a + " in the sensor frame is below this [m]");
    app.add_option("--sensor-max-" + a, f.sensor_frame.max[i],
                   "drop points whose " + a + " in the sensor frame is above this [m]");
  }
  app.add_option("--min-range,--min_range", f.min_range,
                 "drop points nearer the sensor than this [m] (no ray at all); 0: none")
      ->capture_default_str();
}

void add_grid_flags(CLI::App& app, GridPublishConfig& g) {
  app.add_option_function<std::string>(
      "--grid-z",
      [&g](const std::string& v) {
        const size_t colon = v.find(':');
        try {
          size_t used = 0;
          if (colon == std::string::npos) throw std::invalid_argument("no colon");
          g.z_min = std::stod(v.substr(0, colon), &used);
          if (used != colon) throw std::invalid_argument("trailing text");
          g.z_max = std::stod(v.substr(colon + 1), &used);
          g.z_given = true;
          if (used != v.size() - colon - 1) throw std::invalid_argument("trailing text");
        } catch (const std::exception&) {
          throw CLI::ValidationError("--grid-z", "'" + v + "' is not MIN:MAX in metres (e.g. 0.1:1.5)");
        }
      },
      "z band of the published grid, MIN:MAX [m]");
  app.add_option("--grid-rate", g.rate_hz,
                 std::string("publish the 2D grid of the --grid-z band (projected_map rule, grid_t rows) on ") +
                     ort::protocol::kGridChannel + " at this rate [Hz]; 0: off")
      ->check(CLI::Range(0.0, 50.0))
      ->capture_default_str();
  app.add_option("--grid-cell", g.cell_size,
                 "cell size of the published grid [m], a multiple of the resolution; 0: "
                 "the resolution")
      ->capture_default_str();
}

}  // namespace ort::daemon
