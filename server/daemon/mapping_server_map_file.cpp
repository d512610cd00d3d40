// MappingServer and its map file: the map loaded (or a new one, or a prior) at start with its
// identity (docs/PROTOCOL.md "Ids"); the saves are the MapSaver's (daemon/map_saver.h).
#include "daemon/mapping_server.h"

#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <utility>

#include "daemon/map/map_identity.h"
#include "daemon/persistence/map_identity_file.h"
#include "daemon/persistence/map_store.h"

namespace ort::daemon {

// A map that is not complete is never loaded (and so never overwritten by a smaller one):
// the server refuses to start, or with --move-corrupt-map-aside keeps it under another name
// and starts anew.
LoadedMapFile MappingServer::load_checked_map() {
  try {
    return load_map_file(cfg_.map_path, cfg_.engine.resolution, map_load_bound());
  } catch (const MapStoreError& e) {
    if (e.kind() != MapStoreError::Kind::kCorrupt) throw;
    if (!cfg_.move_corrupt_map_aside)
      throw MapStoreError(e.kind(), std::string(e.what()) +
                                        "; the file is left as it is (start with --move-corrupt-map-aside to keep it "
                                        "under another name and start a new map)");
    const std::string aside = move_map_aside(cfg_.map_path);
    for (const char* sidecar : {".order", ".identity"})
      if (std::filesystem::exists(cfg_.map_path + sidecar))
        std::filesystem::rename(cfg_.map_path + sidecar, aside + sidecar);
    log_.warning(text(e.what(), "; moved it to ", aside, " and starting a new map"));
    return {};
  }
}

void MappingServer::take_resolution_from_file() {
  const bool has_map = !cfg_.map_path.empty() && std::filesystem::exists(cfg_.map_path);
  if (!has_map && cfg_.prior_path.empty())
    throw std::runtime_error("no resolution: give -r, or a --map file that exists or a --prior map to take it from");
  const std::string& from = has_map ? cfg_.map_path : cfg_.prior_path;
  cfg_.engine.resolution = map_file_resolution(from);
  log_.info(text("resolution ", cfg_.engine.resolution, " m, from ", from));
}

void MappingServer::load_or_create_map() {
  const double res = cfg_.engine.resolution;
  if (!cfg_.map_path.empty()) check_map_directory_writable(cfg_.map_path);
  LoadedMapFile loaded;
  if (!cfg_.map_path.empty() && std::filesystem::exists(cfg_.map_path)) loaded = load_checked_map();
  if (loaded.tree) {
    map_.tree = std::move(loaded.tree);
    apply_sensor_model(*map_.tree, cfg_.engine.sensor);
    const std::optional<MapIdentityRecord> saved = read_map_identity(cfg_.map_path);
    // The order file's lines past the saved map's (scans a crash lost from it) are cut off,
    // when the identity says which file it was saved with.
    const bool belongs = saved && saved->map_bytes == loaded.bytes && saved->map_hash == loaded.hash;
    const std::string order_path = cfg_.map_path + ".order";
    if (!belongs && std::filesystem::exists(order_path))
      log_.warning(text(order_path,
                        " cannot be matched with this map file (no identity of it): its entries are kept but may not "
                        "match the map"));
    std::map<std::string, std::pair<AppliedEntry, uint64_t>> newest;
    map_.scans = map_.order.open_file(order_path,
                                      belongs ? std::optional<uint64_t>(saved->order_entries) : std::nullopt, &newest);
    for (const auto& [id, at] : newest) {
      map_.newest_scan[robot_key(id)] = {id, at.first.seq, at.second};
      map_.last_scan_utime = std::max(map_.last_scan_utime, at.first.utime);
    }
    const LoadedIdentity id =
        identity_at_load(saved, loaded.bytes, loaded.hash, saver_->absolute_map_path(), map_.scans, new_map_epoch());
    map_.epoch = id.epoch;
    map_.version = id.state_id;
    saver_->mark_saved(map_.version);
    loaded_identity_ = MapIdentityRecord{
        map_.epoch, map_.version, loaded.bytes, loaded.hash, map_.order.size(), false, saver_->absolute_map_path()};
    if (!cfg_.prior_path.empty())
      log_.info(text(cfg_.map_path, " exists: it is loaded, the prior ", cfg_.prior_path,
                     " is not (it was the start of this map, or of another)"));
    char epoch[24];
    std::snprintf(epoch, sizeof epoch, "%llx", static_cast<unsigned long long>(map_.epoch));
    log_.info(text("loaded map ", cfg_.map_path, " (", map_.tree->size(), " nodes, ", map_.order.size(),
                   " scans applied before; map state ", map_.version, " of epoch ", epoch, ": ", id.why, ")"));
    return;
  }
  // A new map, a new history; an order file left without its map (moved aside) starts empty.
  if (!cfg_.map_path.empty()) map_.order.open_file(cfg_.map_path + ".order", 0);
  map_.epoch = new_map_epoch();
  if (!cfg_.prior_path.empty()) {
    // The prior is the new map's first change: state id 1.
    map_.tree = load_prior_map(cfg_.prior_path, res, cfg_.engine.sensor, map_load_bound());
    map_.version = 1;
    log_.info(text("new map from the prior ", cfg_.prior_path, " (", map_.tree->size(), " nodes)",
                   cfg_.map_path.empty() ? "" : ", will be saved to " + cfg_.map_path));
  } else {
    map_.tree = std::make_unique<octomap::OcTree>(res);
    apply_sensor_model(*map_.tree, cfg_.engine.sensor);
    if (!cfg_.map_path.empty()) log_.info(text("new map, will be saved to ", cfg_.map_path));
  }
}

}  // namespace ort::daemon
