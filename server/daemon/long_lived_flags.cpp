#include "daemon/long_lived_flags.h"

#include <stdexcept>
#include <string>

namespace ort::daemon {

void add_long_lived_flags(CLI::App& app, ServerConfig& c) {
  app.add_option("--decay-half-life", c.upkeep.decay_half_life_s,
                 "decay [s]: every voxel's log-odds halves toward 0 (unknown) in this long of the daemon's clock; "
                 "0: no decay")
      ->capture_default_str();
  app.add_option("--decay-step", c.upkeep.decay_step_s, "seconds between decay steps; 0: half-life / 16")
      ->capture_default_str();
  app.add_option("--decay-delete-below", c.upkeep.decay_delete_below,
                 "a voxel whose |log-odds| decays below this is deleted (0.1: p within 0.475..0.525)")
      ->capture_default_str();
  app.add_option("--clear-radius", c.upkeep.clear_radius_m,
                 "clearing by distance [m]: everything farther than this from every robot seen within --clear-recent "
                 "is deleted; 0: off")
      ->capture_default_str();
  app.add_option("--clear-recent", c.upkeep.clear_recent_s,
                 "robots whose scan was applied within this many seconds count for --clear-radius")
      ->capture_default_str();
  app.add_option("--clear-period", c.upkeep.clear_period_s, "seconds between clearing passes")->capture_default_str();
  app.add_option("--region-depth", c.upkeep.region_depth,
                 "octree depth of the regions decay, clearing and the memory bound work on (10: 64 voxels a side)")
      ->capture_default_str();
  app.add_option("--max-map-memory", c.max_map_memory,
                 "octree bytes kept in memory (e.g. 512MiB; 0: no bound); past them the least recently touched "
                 "regions go to FILE.ot.regions/ until touched")
      ->transform(CLI::AsSizeValue(false));
  app.add_option("--working-set-seconds", c.working_set_s,
                 "with --max-map-memory: below the bound, regions touched within this many seconds stay in memory; 0: "
                 "50x the longest mean interval between two scans of one robot, within 1..120 s (5 s until a robot's "
                 "second scan)")
      ->capture_default_str();
  app.add_option("--evict-depth", c.evict_depth,
                 "octree depth of the regions --max-map-memory evicts and restores, --region-depth..16 (0: one "
                 "below --region-depth: 32 voxels a side)")
      ->capture_default_str();
  app.add_option("--region-store-max", c.region_store_max_bytes, "bytes the region store may hold on disk")
      ->transform(CLI::AsSizeValue(false));
}

void check_long_lived_flags(const ServerConfig& c) {
  try {
    validate_upkeep(c.upkeep);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("upkeep", e.what());
  }
  if (const std::string bad = working_set_problem(c.working_set_s); !bad.empty())
    throw CLI::ValidationError("--working-set-seconds", bad);
  if (const std::string bad = memory_bound_problem(c); !bad.empty())
    throw CLI::ValidationError("--max-map-memory", bad);
}

}  // namespace ort::daemon
