#include "daemon/queries/distance_flags.h"

namespace ort::daemon {

void add_distance_flags(CLI::App& app, DistanceServiceConfig& d) {
  app.add_option("--distance-backend", d.backend,
                 "where distance queries run their EDT: cpu (threads), vulkan (the device; fails to start without "
                 "one), auto (the device if it is a GPU, else cpu)")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}))
      ->capture_default_str();
  app.add_option("--distance-threads", d.threads, "CPU threads of a distance query's EDT")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--distance-zstd-level", d.zstd_level,
                 "zstd level of a distance box's field: 1..19, or -1..-50 for zstd's fast levels (the same frames, "
                 "less time, more bytes); 0: sent uncompressed (COMPRESSION_NONE: more chunks)")
      ->check(CLI::Range(-50, 19))
      ->capture_default_str();
  app.add_option("--distance-slab-cells", d.reply_slab_cells,
                 "cells of a distance box reply's z-slab (whole layers): slabs cut, clamped and compressed apart on "
                 "the distance threads, an unchanged slab's frame kept from the last reply; 0: the whole box one zstd "
                 "frame (two with the gradient) made on one thread (the same bytes once decompressed)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 32))
      ->capture_default_str();
  app.add_option("--distance-field-cache", d.field_cache,
                 "keep the last distance field and transform again only where its grid changed (the same answer)")
      ->capture_default_str();
  app.add_option("--distance-change-lists", d.change_lists,
                 "bring the cached field's grid up to date from the scans' change lists instead of reading its box "
                 "from the map again (the same answer; a small cost per scan once distance queries came)")
      ->capture_default_str();
  app.add_option("--distance-device", d.device,
                 "Vulkan device of distance queries (index or name substring; default automatic)");
}

}  // namespace ort::daemon
