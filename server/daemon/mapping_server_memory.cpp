// The server's memory bound (--max-map-memory): daemon/map/map_residency.h.
#include <stdexcept>

#include "daemon/mapping_server.h"
#include "daemon/serving/map_snapshot.h"

namespace ort::daemon {

const MapLoadBound* MappingServer::map_load_bound() {
  if (cfg_.max_map_memory == 0) return nullptr;
  if (load_bound_) return &*load_bound_;
  if (const std::string bad = memory_bound_problem(cfg_); !bad.empty())
    throw std::invalid_argument("--max-map-memory " + bad);
  const std::string dir = region_store_dir(cfg_.map_path);
  // Not durable: the store is emptied at every start (below), so its files need not survive a
  // power cut, and an fsync per evicted region would cost every eviction a disk round trip.
  region_store_ = std::make_unique<RegionStore>(dir, cfg_.region_store_max_bytes, /*durable=*/false);
  // Every save is the whole map (its copy gets the evicted regions back), so what a previous
  // run left here is in the map file as of its last save, or newer than it (evicted after
  // it, lost with that run's unsaved scans): the map file is the map of record.
  const std::vector<RegionId> left = region_store_->ids();
  for (RegionId id : left) region_store_->erase(id);
  if (!left.empty())
    log_.info(text("removed ", left.size(), " regions a previous run left in ", dir,
                   " (the map file holds the map as it was saved)"));
  const RegionGrid grid = region_grid(evict_region_depth(cfg_));
  residency_ =
      std::make_unique<MapResidency>(map_, grid, *region_store_, cfg_.max_map_memory, log_, cfg_.working_set_s);
  // The file's regions past the low-water mark go straight to the store as it loads.
  load_bound_ =
      MapLoadBound{grid, static_cast<uint64_t>(MapResidency::kLowWater * double(cfg_.max_map_memory)),
                   [r = residency_.get()](RegionId id, std::span<const uint8_t> bytes) { r->adopt_loaded(id, bytes); }};
  return &*load_bound_;
}

void MappingServer::open_memory_bound() {
  if (cfg_.max_map_memory == 0) return;
  map_load_bound();  // no map file was loaded: the store and residency are made here
  map_.residency = residency_.get();
  residency_->enforce(*map_.tree);  // a map larger than the bound (a prior) goes down to it now
  const MapResidencyStats s = residency_->stats();
  log_.info(text("map memory bound ", cfg_.max_map_memory, " bytes: ", s.resident_bytes, " resident, ",
                 s.evicted_regions, " regions (", s.evicted_bytes, " bytes) in ", region_store_dir(cfg_.map_path), ", ",
                 s.evictions, " of them evicted after the load"));
}

std::unique_ptr<octomap::OcTree> MappingServer::whole_map() { return copy_map(map_).tree; }

}  // namespace ort::daemon
