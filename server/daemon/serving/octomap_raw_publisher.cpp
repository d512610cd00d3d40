#include "daemon/serving/octomap_raw_publisher.h"

#include <cmath>
#include <fstream>
#include <shared_mutex>

#include "daemon/map/map_replica.h"
#include "daemon/serving/map_snapshot.h"
#include "daemon/serving/octomap_raw_map.h"

namespace ort::daemon {

size_t octomap_raw_default_cap() {
  std::ifstream in("/proc/sys/net/core/rmem_default");
  size_t rmem_default = 0;
  if (!(in >> rmem_default) || rmem_default == 0) return 190 * 1024;
  return rmem_default / 10 * 9;
}

OctomapRawPublisher::OctomapRawPublisher(const OctomapRawConfig& cfg, MapState& map, LcmLoop& loop, Log log)
    : cfg_(cfg), map_(map), loop_(loop), log_(std::move(log)) {
  if (cfg_.max_bytes == 0) cfg_.max_bytes = octomap_raw_default_cap();
}

OctomapRawPublisher::~OctomapRawPublisher() { stop(); }

void OctomapRawPublisher::start() {
  if (cfg_.rate_hz <= 0 || periodic_.running()) return;
  log_.info(text("publishing the map as octomap.raw_t on ", cfg_.channel, " at ", cfg_.rate_hz, " Hz (cap ",
                 cfg_.max_bytes / 1024, " KiB)"));
  PeriodicOptions o;
  o.run_first = true;
  periodic_.start(
      1.0 / cfg_.rate_hz, [this] { publish_newest(); }, o);
}

void OctomapRawPublisher::stop() { periodic_.stop(); }

std::string OctomapRawPublisher::note() const {
  std::lock_guard lock(note_mutex_);
  return note_;
}

void OctomapRawPublisher::encode_if_changed() {
  RawMap raw;
  const RawMapOptions options{cfg_.max_bytes, cfg_.min_depth};
  const bool band = std::isfinite(cfg_.occupancy_min_z) || std::isfinite(cfg_.occupancy_max_z);
  if (auto v = readable_version(map_)) {
    // A version of the read replica: the tree made from it is the viewer's own (the band
    // filter may change it), and no lock the octree stage or the replica waits for is held.
    if (v->version == encoded_version_) return;
    encoded_version_ = v->version;
    const std::unique_ptr<octomap::OcTree> tree = v->map->tree();
    if (band) drop_occupied_outside_band(*tree, cfg_.occupancy_min_z, cfg_.occupancy_max_z);
    raw = make_raw_map(*tree, v->last_scan_utime, options);
    ++encodings_;
  } else if (map_.replica && !band) {
    // Without versions: encoded straight from the read replica, under its lock (its thread waits).
    MapState& r = readable_map(map_);
    std::shared_lock lock(r.mutex);
    if (r.version == encoded_version_) return;
    encoded_version_ = r.version;
    raw = make_raw_map(*r.tree, r.last_scan_utime, options);
    ++encodings_;
  } else {
    // The band filter changes the tree it encodes: a copy (of the replica when there is one).
    auto copy = copy_map_if_changed(readable_map(map_), encoded_version_);
    if (!copy) return;
    ++map_copies_;
    encoded_version_ = copy->version;
    if (band) drop_occupied_outside_band(*copy->tree, cfg_.occupancy_min_z, cfg_.occupancy_max_z);
    raw = make_raw_map(*copy->tree, copy->last_scan_utime, options);
    ++encodings_;
  }
  encoded_.clear();
  if (raw.message) {
    encoded_.resize(static_cast<size_t>(raw.message->getEncodedSize()));
    raw.message->encode(encoded_.data(), 0, static_cast<int>(encoded_.size()));
  }
  std::lock_guard lock(note_mutex_);
  if (raw.note != note_ && !raw.note.empty()) log_.warning(raw.note);
  note_ = raw.note;
}

void OctomapRawPublisher::publish_newest() {
  try {
    encode_if_changed();
    if (!encoded_.empty() && loop_.publish(cfg_.channel, encoded_.data(), encoded_.size()) == 0) ++published_;
  } catch (const std::exception& e) {  // a failed encoding must not end the server
    log_.error(text(cfg_.channel, " not published: ", e.what()));
  }
}

}  // namespace ort::daemon
