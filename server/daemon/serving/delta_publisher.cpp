#include "daemon/serving/delta_publisher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/clock.h"
#include "daemon/map/delta_changes.h"
#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_delta_t.hpp"
#include "protocol/delta_codec.h"
#include "protocol/limits.h"
#include "protocol/zstd_codec.h"

namespace ort::daemon {
namespace {

using Delta = octomap_rt::map_delta_t;
using protocol::VoxelChange;

}  // namespace

DeltaPublisher::DeltaPublisher(LcmLoop& loop, DeltaConfig cfg, std::function<int64_t()> latest_snapshot_id, Log log)
    : loop_(loop), cfg_(std::move(cfg)), latest_snapshot_id_(std::move(latest_snapshot_id)), log_(std::move(log)) {}

DeltaPublisher::~DeltaPublisher() {
  try {
    stop();
  } catch (...) {}
}

void DeltaPublisher::start(uint64_t version, uint64_t epoch) {
  from_version_ = to_version_ = version;
  epoch_ = epoch;
  PeriodicOptions o;
  o.run_on_stop = true;  // what is pending goes out
  periodic_.start(
      1.0 / std::max(cfg_.max_rate_hz, 1e-3), [this] { flush_or_log(); }, o);
}

void DeltaPublisher::stop() { periodic_.stop(); }

// Called by stage 2 under the map lock, so its time is the pipeline's: looking each voxel up
// in the tree again cost stage 2 more than the rest of the delta work (the log's "map deltas
// from inside the octree update"). The octree stage's own log is swapped in instead, and
// classified on the publisher's thread.
void DeltaPublisher::applied(LeafChanges& changes, const octomap::OcTree& tree, uint64_t version) {
  std::lock_guard lock(mutex_);
  pending_.push_back(std::move(changes));
  if (!spare_.empty()) {
    changes = std::move(spare_.back());
    spare_.pop_back();
  } else {
    changes = LeafChanges{};
  }
  occupancy_thres_log_ = tree.getOccupancyThresLog();
  to_version_ = version;
  pending_scans_++;
}

void DeltaPublisher::give_back(std::vector<LeafChanges>& logs) {
  // About the scans of one set (300 scans/s at 10 sets/s): most scans then find a log whose
  // lanes need not grow (growing them would be stage 2's time, under the map lock). Holds no
  // more memory than the logs of one set held anyway.
  constexpr size_t kMaxSpare = 48;
  std::lock_guard lock(mutex_);
  while (!logs.empty() && spare_.size() < kMaxSpare) {
    spare_.push_back(std::move(logs.back()));
    logs.pop_back();
  }
}

void DeltaPublisher::replaced(const octomap::OcTree&, uint64_t version, uint64_t epoch) {
  std::lock_guard lock(mutex_);
  pending_.clear();
  pending_scans_ = 0;
  from_version_ = to_version_ = version;
  epoch_ = epoch;
  skip_seqs_++;
}

DeltaStats DeltaPublisher::stats() const {
  std::lock_guard lock(mutex_);
  DeltaStats s = stats_;
  s.last_seq = last_seq_;
  return s;
}

void DeltaPublisher::flush_or_log() {
  try {
    flush();
  } catch (const std::exception& e) {
    log_.error(text("map delta failed: ", e.what()));
  }
}

void DeltaPublisher::flush() {
  std::vector<LeafChanges> logs;
  uint64_t from, to, epoch;
  int64_t scans;
  float thr;
  {
    std::lock_guard lock(mutex_);
    if (pending_.empty() && skip_seqs_ == 0) return;  // versions keep accumulating into the next set
    logs.swap(pending_);
    thr = occupancy_thres_log_;
    from = from_version_;
    to = to_version_;
    epoch = epoch_;
    from_version_ = to;
    scans = pending_scans_;
    pending_scans_ = 0;
    next_seq_ += skip_seqs_;
    skip_seqs_ = 0;
  }
  std::vector<VoxelChange> set;
  for (const LeafChanges& log : logs) append_delta_changes(log, cfg_.exact, thr, set);
  keep_newest_per_key(set);
  give_back(logs);
  const int8_t mode = cfg_.exact ? Delta::MODE_LOG_ODDS : Delta::MODE_CLASS;
  auto parts = protocol::encode_delta_parts(set, mode, std::max(cfg_.zstd_level, 1), protocol::kDeltaDataBytes);
  // An empty set still goes out: after replaced() it carries the gap to the mirrors, and when
  // the period's scans changed nothing a mirror sees it moves the mirrors to `to`. Without it
  // a mirror stayed at an older version for as long as such scans came (a robot standing in a
  // mapped room) and waiting for its own scan's version never ended. At most max_rate_hz sets
  // a second, ~100 bytes each.
  if (parts.empty()) parts.push_back(protocol::DeltaPart{0, 0, protocol::zstd_compress("", 1)});
  Delta d{};
  d.from_version = static_cast<int64_t>(from);
  d.to_version = static_cast<int64_t>(to);
  d.map_epoch = static_cast<int64_t>(epoch);
  d.snapshot_id = latest_snapshot_id_ ? latest_snapshot_id_() : -1;
  d.num_parts = static_cast<int32_t>(parts.size());
  d.mode = mode;
  d.compression = octomap_rt::map_chunk_t::COMPRESSION_ZSTD;
  d.resolution = cfg_.resolution;
  d.server_id = cfg_.server_id;
  int64_t bytes = 0;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(cfg_.part_interval_ms));
    d.utime = now_utime();
    d.delta_seq = next_seq_++;
    d.part_index = static_cast<int32_t>(i);
    d.num_voxels = parts[i].num_voxels;
    d.uncompressed_size = parts[i].uncompressed_size;
    d.data.assign(parts[i].data.begin(), parts[i].data.end());
    d.data_size = static_cast<int32_t>(d.data.size());
    loop_.publish(cfg_.channel, d);
    last_seq_ = d.delta_seq;
    bytes += d.getEncodedSize();
  }
  std::lock_guard lock(mutex_);
  stats_.messages += static_cast<int64_t>(parts.size());
  stats_.sets++;
  stats_.bytes += bytes;
  stats_.voxels += static_cast<int64_t>(set.size());
  stats_.scans += scans;
}

}  // namespace ort::daemon
