#include "daemon/serving/snapshot_store.h"

#include <stdexcept>
#include <thread>

#include "core/clock.h"
#include "core/file_checks/octree_binary.h"
#include "daemon/map/map_replica.h"
#include "daemon/serving/map_snapshot.h"
#include "octomap_rt/map_chunk_t.hpp"

namespace ort::daemon {

std::shared_ptr<const SnapshotBlob> SnapshotStore::latest(MapState& map, int8_t format, bool fresh, bool& took_new) {
  took_new = false;
  const auto min_interval =
      std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(policy_.min_interval_s));
  if (fresh && !kept_.empty()) std::this_thread::sleep_until(taken_at_ + min_interval);
  const auto now = SteadyClock::now();
  const bool old_enough = kept_.empty() || now - taken_at_ >= min_interval;
  if (old_enough) {
    uint64_t version;
    {
      std::shared_lock lock(map.mutex);
      const MapHoldNote note(map.holders, "snapshot id check");
      version = map.version;
    }
    if (kept_.empty() || version != kept_.back().contents.snapshot_id) {
      take(map);
      took_new = true;
    }
  }
  return blob_of(kept_.back(), format);
}

std::shared_ptr<const SnapshotBlob> SnapshotStore::find(uint64_t id, int8_t format) {
  for (Entry& e : kept_)
    if (e.contents.snapshot_id == id) {
      if (e.blob[format] || e.tree || e.version) return blob_of(e, format);
      return nullptr;  // an older snapshot never made in this format
    }
  return nullptr;
}

void SnapshotStore::take(MapState& map) {
  Entry e;
  if (auto v = readable_version(map)) {
    // A version of the read replica: no copy, and no lock the octree stage or the replica
    // waits for.
    e.contents = describe_snapshot_producers(v->newest_scan, v->scans, v->last_scan_utime);
    if (v->map->nodes() > 0) {
      v->map->metric_min(e.contents.bbox_min[0], e.contents.bbox_min[1], e.contents.bbox_min[2]);
      v->map->metric_max(e.contents.bbox_max[0], e.contents.bbox_max[1], e.contents.bbox_max[2]);
    }
    e.contents.snapshot_id = v->version;
    e.contents.epoch = v->epoch;
    e.version = std::move(v);
  } else {
    MapCopy copy = copy_map(readable_map(map));  // the replica's copy holds only the replica
    e.contents = describe_snapshot(*copy.tree, copy.newest_scan, copy.scans, copy.last_scan_utime);
    e.contents.snapshot_id = copy.version;
    e.contents.epoch = copy.epoch;
    e.contents.copy_lock_ms = copy.lock_ms;
    e.tree = std::move(copy.tree);
  }
  if (!kept_.empty()) kept_.back().tree.reset(), kept_.back().version.reset();
  kept_.push_back(std::move(e));
  while (kept_.size() > std::max<size_t>(policy_.kept, 1)) kept_.pop_front();
  taken_at_ = SteadyClock::now();
  latest_id_ = static_cast<int64_t>(kept_.back().contents.snapshot_id);
  taken_++;
}

std::shared_ptr<const SnapshotBlob> SnapshotStore::blob_of(Entry& e, int8_t format) {
  if (format < 1 || format > 2) throw std::invalid_argument("unknown snapshot format");
  if (!e.blob[format]) {
    if (e.version && format == octomap_rt::map_chunk_t::FORMAT_OCTOMAP_FULL) {
      const auto t0 = SteadyClock::now();  // the .ot is the version's bytes written in order
      std::string raw = e.version->map->ot_bytes();
      e.blob[format] = std::make_shared<const SnapshotBlob>(
          make_snapshot_blob_of_bytes(std::move(raw), e.contents, format, policy_.zstd_level, ms_since(t0)));
    } else if (e.version) {
      const auto t0 = SteadyClock::now();  // the .bt: of the tree made from the version
      const std::unique_ptr<octomap::OcTree> tree = e.version->map->tree();
      std::string raw = octomap_binary_bytes(*tree);
      e.blob[format] = std::make_shared<const SnapshotBlob>(
          make_snapshot_blob_of_bytes(std::move(raw), e.contents, format, policy_.zstd_level, ms_since(t0)));
    } else if (e.tree) {
      e.blob[format] =
          std::make_shared<const SnapshotBlob>(make_snapshot_blob(*e.tree, e.contents, format, policy_.zstd_level));
    } else {
      return nullptr;
    }
    last_made_ = e.blob[format];
  }
  return e.blob[format];
}

}  // namespace ort::daemon
