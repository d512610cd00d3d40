// Publishes the map as `octomap.raw_t` on OCTOMAP (--octomap-raw-rate HZ, off by default),
// for the viewers LCM users already run (libbot's octomap renderer, Director's vtkOctomap,
// lcmoctomap.py). A thread of its own: every period it copies the map if it changed (under
// the map lock, as saves do), encodes it outside the lock within the size cap (see
// octomap_raw_map.h), and publishes the newest encoding, so a viewer that starts later still
// gets the map at the next period.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include "core/log.h"
#include "core/threads/periodic_thread.h"
#include "daemon/map/map_state.h"
#include "daemon/transport/lcm_loop.h"
#include "protocol/channels.h"

namespace ort::daemon {

// The map for LCM's OctoMap viewers (octomap.raw_t).
struct OctomapRawConfig {
  double rate_hz = 0;  // 0: off
  std::string channel = ort::protocol::kOctomapRawChannel;
  size_t max_bytes = 0;     // whole message; 0: octomap_raw_default_cap()
  unsigned min_depth = 10;  // coarsest depth-limited map sent before giving up
  // octomap_server's occupancy_min_z/max_z: occupied cells shown only strictly inside the band.
  double occupancy_min_z = -std::numeric_limits<double>::infinity();
  double occupancy_max_z = std::numeric_limits<double>::infinity();
};

// 90 % of net.core.rmem_default: a receiver that keeps the default UDP buffer (Java's LCM
// cannot raise it; most C programs don't) gets a message only if all of its fragments fit
// at once (measured: 3 datagrams of 65 KB fit in the default 208 KiB, a 4th is dropped).
// 190 KiB when rmem_default cannot be read.
size_t octomap_raw_default_cap();

class OctomapRawPublisher {
 public:
  OctomapRawPublisher(const OctomapRawConfig& cfg, MapState& map, LcmLoop& loop, Log log);
  ~OctomapRawPublisher();
  OctomapRawPublisher(const OctomapRawPublisher&) = delete;
  OctomapRawPublisher& operator=(const OctomapRawPublisher&) = delete;

  void start();
  void stop();  // idempotent
  // For the status: "" while the whole map goes out; else what was cut or why nothing is sent.
  std::string note() const;
  int64_t published() const { return published_; }
  // Whole-map copies made under a lock (only when the map changed, and with a read replica
  // only without versions, to drop cells outside the occupancy band) and encodings made (one
  // per map version; a tree made from a replica's version is the publisher's own, no copy).
  int64_t map_copies() const { return map_copies_; }
  int64_t encodings() const { return encodings_; }

 private:
  void publish_newest();  // the periodic task
  void encode_if_changed();

  OctomapRawConfig cfg_;
  MapState& map_;
  LcmLoop& loop_;
  Log log_;
  uint64_t encoded_version_ = UINT64_MAX;
  std::vector<uint8_t> encoded_;  // newest message; empty when the map is too large
  mutable std::mutex note_mutex_;
  std::string note_;
  std::atomic<int64_t> published_{0};
  std::atomic<int64_t> map_copies_{0};
  std::atomic<int64_t> encodings_{0};
  PeriodicThread periodic_;  // last: stopped before the members its task uses go
};

}  // namespace ort::daemon
