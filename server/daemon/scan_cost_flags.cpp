#include "daemon/scan_cost_flags.h"

#include <cstdlib>
#include <string>

namespace ort::daemon {
namespace {

// CLI::Range lets NaN through (every comparison with it is false), and a NaN rate or
// allowance turned its bound off: refill() made the tokens NaN, never below zero.
CLI::Validator number_in(double lo, double hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !(v >= lo && v <= hi)) return "must be a number in " + range;
        return {};
      },
      "NUMBER in " + range);
}

}  // namespace

void add_scan_cost_flags(CLI::App& app, ScanCostBounds& c) {
  app.add_option("--max-origin-jump", c.max_origin_jump_m,
                 "farthest a robot's scan origin may be from its last scan's [m] (plus --max-robot-speed for each "
                 "second since); farther: rejected as 'origin jump'; 0: unchecked")
      ->capture_default_str()
      ->check(number_in(0.0, 1e7));
  app.add_option("--max-robot-speed", c.max_speed_mps, "see --max-origin-jump [m/s]")
      ->capture_default_str()
      ->check(number_in(0.0, 1e6));
  app.add_option("--max-scan-voxels", c.max_scan_voxels,
                 "most voxels one scan may update; more: rejected as 'too many voxels'; 0: no limit")
      ->capture_default_str();
  app.add_option("--max-mean-ray-voxels", c.max_mean_ray_voxels,
                 "longest a scan's rays may be on average, in voxels (each cut at the max range); longer: "
                 "rejected as 'rays too long on average' before any ray is shot (a few points far out cost what "
                 "a real scan's thousands do); 0: no limit")
      ->capture_default_str()
      ->check(number_in(0.0, 1e9));
  app.add_option("--max-new-nodes-per-s", c.max_new_nodes_per_s,
                 "new octree nodes a second one robot may add, on average (allowance up to --new-node-burst); "
                 "past it its scans are rejected as 'new-node rate' until the allowance refills; 0: no limit")
      ->capture_default_str()
      ->check(number_in(0.0, 1e12));
  app.add_option("--new-node-burst", c.new_node_burst, "see --max-new-nodes-per-s")
      ->capture_default_str()
      ->check(number_in(0.0, 1e13));
  app.add_option("--max-map-new-nodes-per-s", c.max_map_new_nodes_per_s,
                 "new octree nodes a second all robots together may add, on average (allowance up to "
                 "--map-new-node-burst); past it scans are rejected as 'map new-node rate'; 0: no limit")
      ->capture_default_str()
      ->check(number_in(0.0, 1e12));
  app.add_option("--map-new-node-burst", c.map_new_node_burst, "see --max-map-new-nodes-per-s")
      ->capture_default_str()
      ->check(number_in(0.0, 1e13));
  app.add_option("--producer-share", c.producer_share,
                 "share the stages' time among producers: each robot with history (--share-history-scans over "
                 "--share-history) has a share, robot ids without share one; a scan that waits past the latency "
                 "bound while others were served in its turn is dropped as 'over its share'; false: one FIFO in "
                 "arrival order")
      ->capture_default_str();
  app.add_option("--share-history-scans", c.share_history_scans,
                 "valid scans a robot must have sent (over --share-history) before it has a share of its own")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{1'000'000'000}));
  app.add_option("--share-history", c.share_history_s, "see --share-history-scans [s]")
      ->capture_default_str()
      ->check(number_in(0.0, 1e9));
  app.add_option("--shared-class-share", c.shared_class_share,
                 "the share of the stages all robot ids without history get together, against 1 for each robot "
                 "with history")
      ->capture_default_str()
      ->check(number_in(1e-3, 1e3));
  app.add_option(
         "--max-scan-time", c.max_scan_stage_s,
         "most of the stages' time one scan of a robot without history (--share-history-scans) may be predicted to take (its rays' voxels times what a voxel "
         "of scans of its shape took before) while other robots stream; more: rejected as 'predicted "
         "too slow' before any ray is shot; 0: no limit [s]")
      ->capture_default_str()
      ->check(number_in(0.0, 1e6));
  SharedClassBounds& sh = c.shared;
  app.add_option("--shared-budget", sh.enabled,
                 "bound what robot ids without history take of the stages: per scan while others stream "
                 "(--shared-scan-*, --shared-unknown-ray-*: past it rejected as 'predicted too slow' before it is "
                 "shot), per second while a robot with history streams (--shared-stage-*: past it the scans wait); "
                 "false: only their share bounds them")
      ->capture_default_str();
  app.add_option("--shared-unknown-ray-floor", sh.unknown_ray_floor_voxels,
                 "see --shared-budget: a scan whose rays are longer on average than this many voxels and than "
                 "--shared-unknown-ray-ratio times the longest shape applied has no known cost")
      ->capture_default_str()
      ->check(number_in(1.0, 1e9));
  app.add_option("--shared-unknown-ray-ratio", sh.unknown_ray_ratio, "see --shared-unknown-ray-floor")
      ->capture_default_str()
      ->check(number_in(1.0, 1e6));
  app.add_option("--shared-unknown-walk-floor", sh.unknown_walk_floor_voxels,
                 "see --shared-unknown-ray-floor: only a scan walking more voxels in all (rays x mean length) than "
                 "this is refused for an unknown cost")
      ->capture_default_str()
      ->check(number_in(0.0, 1e12));
  app.add_option("--shared-stage-floor", sh.floor_ms_per_s, "see --shared-budget [ms of the stages a second]")
      ->capture_default_str()
      ->check(number_in(0.0, 1e6));
  app.add_option("--shared-stage-ratio", sh.robot_ratio, "see --shared-budget")
      ->capture_default_str()
      ->check(number_in(0.0, 1e3));
  app.add_option("--shared-stage-burst", sh.burst_ms, "see --shared-budget [ms]")
      ->capture_default_str()
      ->check(number_in(0.0, 1e7));
  app.add_option("--shared-scan-floor", sh.scan_floor_ms,
                 "see --shared-budget: while others stream, a scan of a robot id without history predicted (from "
                 "scans of its shape) to take more than this or --shared-scan-ratio times the robots' mean scan is "
                 "rejected as 'predicted too slow' [ms]")
      ->capture_default_str()
      ->check(number_in(0.0, 1e7));
  app.add_option("--shared-scan-ratio", sh.scan_ratio, "see --shared-scan-floor")
      ->capture_default_str()
      ->check(number_in(0.0, 1e6));
}

}  // namespace ort::daemon
