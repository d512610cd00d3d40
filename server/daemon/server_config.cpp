#include "daemon/server_config.h"

#include <unistd.h>

#include <algorithm>
#include <string>

#include "daemon/intake/producer_registry.h"

namespace ort::daemon {

uint64_t automatic_queue_budget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  const uint64_t phys = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : (4ull << 30);
  return std::clamp<uint64_t>(phys / 64, 64ull << 20, 1ull << 30);
}

std::string working_set_problem(double seconds) {
  constexpr double kMaxSeconds = 30 * 86400.0;
  if (seconds == 0 || (seconds > 0 && seconds <= kMaxSeconds)) return "";  // NaN fails both
  return "--working-set-seconds must be 0 (the scan rate's) or seconds in (0, 2592000]";
}

std::string memory_bound_problem(const ServerConfig& c) {
  constexpr uint64_t kMin = uint64_t(1) << 20, kMax = uint64_t(1) << 50;
  if (c.max_map_memory == 0) return "";
  if (c.max_map_memory < kMin || c.max_map_memory > kMax)
    return "must be 0 (no bound) or a number of bytes in [1 MiB, 2^50]";
  if (const std::string bad = working_set_problem(c.working_set_s); !bad.empty()) return bad;
  if (c.region_store_max_bytes < kMin || c.region_store_max_bytes > kMax)
    return "--region-store-max must be a number of bytes in [1 MiB, 2^50]";
  if (c.evict_depth != 0 && (c.evict_depth < c.upkeep.region_depth || c.evict_depth > 16))
    return "--evict-depth must be 0 (one below --region-depth) or between --region-depth (" +
           std::to_string(c.upkeep.region_depth) + ") and 16";
  if (c.map_path.empty()) return "needs --map: evicted regions are kept in FILE.ot.regions/ beside the map file";
  if (c.queries.grid.rate_hz > 0)
    return "cannot go with --grid-rate: its whole-map grid would bring every evicted region back each period "
           "(ask for windowed grids instead)";
  return "";
}

unsigned evict_region_depth(const ServerConfig& c) {
  return c.evict_depth != 0 ? c.evict_depth : std::min(16u, c.upkeep.region_depth + 1);
}

unsigned replica_version_depth(const ServerConfig& c) {
  return c.replica_version_depth != 0 ? std::min(16u, c.replica_version_depth) : evict_region_depth(c);
}

ProducerPolicy producer_policy(const ServerConfig& c) {
  ProducerPolicy p;
  p.max_producers = c.max_producers;
  p.idle_release = std::chrono::duration<double>(c.producer_idle_release_s);
  p.allowed_robots = c.allowed_robots;
  p.history_scans = c.scan_costs.share_history_scans;
  p.history = std::chrono::duration<double>(c.scan_costs.share_history_s);
  return p;
}

}  // namespace ort::daemon
