#include "daemon/queries/distance_flags.h"

#include <algorithm>
#include <stdexcept>

#include "core/errors.h"
#include "engine/distance_device.h"

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

DistanceBackend choose_distance_backend(const std::string& backend, const std::string& device_name, int threads_asked) {
  if (backend != "cpu" && backend != "vulkan" && backend != "auto")
    throw std::invalid_argument("--distance-backend must be cpu, vulkan or auto, not '" + backend + "'");
  if (backend != "cpu") {
    try {
      EdtDevice device = open_edt_device(device_name);
      if (backend == "vulkan" || !device.cpu_implementation) {
        DeviceEdt run = std::move(device.run);
        return {[run](std::span<const uint8_t> occ, distance::GridDims g, std::span<uint32_t> out) {
                  run(occ, g.nx, g.ny, g.nz, out);
                },
                "vulkan (" + device.name + ")"};
      }
    } catch (const Unsupported&) {
      if (backend == "vulkan") throw;
    }
  }
  const int threads = std::max(1, threads_asked);
  return {distance::cpu_edt(threads), "cpu (" + std::to_string(threads) + " threads)"};
}

}  // namespace ort::daemon
