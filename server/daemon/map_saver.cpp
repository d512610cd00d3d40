#include "daemon/map_saver.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>

#include "core/clock.h"
#include "daemon/map/map_replica.h"
#include "daemon/persistence/map_store.h"
#include "daemon/serving/map_snapshot.h"

namespace ort::daemon {

MapSaver::MapSaver(std::string map_path, double interval_s, MapState& map, Log log)
    : path_(std::move(map_path)), interval_s_(interval_s), map_(map), log_(std::move(log)) {}

std::string MapSaver::absolute_map_path() const {
  std::error_code ec;
  const auto abs = std::filesystem::absolute(path_, ec);
  return ec ? path_ : abs.lexically_normal().string();
}

void MapSaver::write_identity(const MapIdentityRecord& r) {
  write_file_atomically(identity_path(path_), format_map_identity(r));
}

void MapSaver::start() {
  if (path_.empty() || interval_s_ <= 0) return;
  periodic_.start(interval_s_, [this] { save_periodically(); });
}

void MapSaver::stop() { periodic_.stop(); }

void MapSaver::save_periodically() {
  std::string error;
  try {
    save(false);
  } catch (const std::exception& e) {
    error = e.what();
    log_.error(text("save failed (the previous map file is intact): ", error));
  }
  std::lock_guard lock(error_mutex_);
  last_error_ = error;  // the status is DEGRADED while it is set
}

void MapSaver::save(bool force, bool clean, bool from_record) {
  if (path_.empty()) return;
  std::lock_guard save_lock(save_mutex_);
  const auto t0 = SteadyClock::now();
  // A version of the read replica when there is one (no copy, no lock anyone waits for);
  // else a copy under its lock (a state between two whole scans), serialized outside it.
  std::string bytes;
  uint64_t version = 0, epoch = 0;
  size_t scans = 0;
  double lock_ms = 0;
  // The final save reads the map of record (the stages have stopped): a read replica still
  // behind it would make the stop wait for the replica's backlog.
  if (auto v = from_record ? nullptr : readable_version(map_)) {
    if (!force && v->version == saved_version_) return;
    bytes = v->map->ot_bytes();
    version = v->version, epoch = v->epoch, scans = v->scans;
  } else {
    MapState& source = from_record ? map_ : readable_map(map_);
    std::optional<MapCopy> copy =
        force ? std::optional<MapCopy>(copy_map(source)) : copy_map_if_changed(source, saved_version_);
    if (!copy) return;
    bytes = serialize_map(*copy->tree);
    version = copy->version, epoch = copy->epoch, scans = copy->scans, lock_ms = copy->lock_ms;
  }
  map_.order.sync();
  write_file_atomically(path_, bytes);
  write_identity(
      MapIdentityRecord{epoch, version, bytes.size(), map_file_hash(bytes), scans, clean, absolute_map_path()});
  saved_version_ = version;
  saves_++;
  last_save_utime_ = now_utime();
  max_save_lock_ms_ = std::max(max_save_lock_ms_.load(), lock_ms);
  last_save_ms_ = ms_since(t0);
}

std::string MapSaver::save_final() {
  if (path_.empty()) return "";
  // A failed final save is reported (log, summary, status, exit status), not thrown.
  try {
    save(/*force=*/true, /*clean=*/true, /*from_record=*/true);
    return "";
  } catch (const std::exception& e) {
    log_.error(text("the final save failed (the previous map file is intact): ", e.what()));
    return e.what();
  }
}

SaveFigures MapSaver::figures() const {
  SaveFigures f;
  f.saves = saves_;
  f.last_save_utime = last_save_utime_;
  f.last_save_ms = last_save_ms_;
  f.max_save_lock_ms = max_save_lock_ms_;
  std::lock_guard lock(error_mutex_);
  f.last_error = last_error_;
  return f;
}

}  // namespace ort::daemon
