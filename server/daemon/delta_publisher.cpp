#include "daemon/delta_publisher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_delta_t.hpp"
#include "protocol/delta_codec.h"
#include "protocol/map_protocol.h"
#include "protocol/zstd_codec.h"

namespace ort::daemon {
namespace {

using Delta = octomap_rt::map_delta_t;
using protocol::VoxelChange;

int64_t utime_now() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The class a voxel had before this scan's update `u` made it `after`: 0 = unknown (no
// node), else CLASS_*. -1 when it cannot be told apart safely (then the voxel is sent).
int class_before(const octomap::OcTree& t, float after, float u) {
  const float lo = t.getClampingThresMinLog(), hi = t.getClampingThresMaxLog(), thr = t.getOccupancyThresLog();
  const bool clamped = (u > 0 && after >= hi) || (u < 0 && after <= lo);
  if (clamped) {
    // Was within |u| of the bound on its side: the bound's class, if |u| cannot cross the threshold.
    const float bound = u > 0 ? hi : lo;
    if (std::fabs(bound - thr) <= std::fabs(u) + 1e-4f) return -1;
    return bound >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
  }
  const float before = after - u;
  if (before == 0.0f) return 0;  // a new node starts at 0 (or an old one at exactly 0: sent anyway)
  if (std::fabs(before) < 1e-4f || std::fabs(before - thr) < 1e-4f) return -1;
  return before >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
}

}  // namespace

DeltaPublisher::DeltaPublisher(LcmLoop& loop, DeltaConfig cfg, std::function<int64_t()> latest_snapshot_id,
                               std::ostream& log)
    : loop_(loop), cfg_(std::move(cfg)), latest_snapshot_id_(std::move(latest_snapshot_id)), log_(log) {}

DeltaPublisher::~DeltaPublisher() {
  try {
    stop();
  } catch (...) {
  }
}

void DeltaPublisher::start(uint64_t version) {
  from_version_ = to_version_ = version;
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

void DeltaPublisher::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

// The changes among voxels [begin, end) of one scan's list (see the header: class or exact mode).
std::vector<VoxelChange> DeltaPublisher::changes_in(const VoxelList& voxels, size_t begin, size_t end,
                                                    const octomap::OcTree& tree) const {
  const float hit = tree.getProbHitLog(), miss = tree.getProbMissLog(), thr = tree.getOccupancyThresLog();
  std::vector<VoxelChange> changed;
  changed.reserve(cfg_.exact ? end - begin : (end - begin) / 8);
  for (size_t i = begin; i < end; ++i) {
    const VoxelUpdate& v = voxels[i];
    const octomap::OcTreeKey key = v.key();
    const octomap::OcTreeNode* node = tree.search(key);
    if (!node) continue;  // cannot happen after an update; nothing to report
    const float after = node->getLogOdds();
    const int8_t now_class = after >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
    if (cfg_.exact) {
      changed.push_back({protocol::pack_key(key), after});
    } else if (class_before(tree, after, v.occupied() ? hit : miss) != now_class) {
      changed.push_back({protocol::pack_key(key), static_cast<float>(now_class)});
    }
  }
  return changed;
}

// Called by stage 2 under the map lock, so its time is the pipeline's: done on one thread
// with a hash-map insert per change, it took two thirds of stage 2 on RGB-D scans (H200,
// docs/BENCHMARKS.md "Performance (issue 12)"). The tree is only read here, so the look-ups
// are split over threads (chunks of at least kMinChunk voxels, appended in the list's order,
// so the result is the one-thread result), and the changes are only appended: flush() sorts
// them and keeps each key's newest value, on the publisher's thread.
void DeltaPublisher::applied(const VoxelList& voxels, const octomap::OcTree& tree, uint64_t version) {
  constexpr size_t kMinChunk = 16384;
  const size_t n = voxels.size();
  const size_t chunks = std::clamp<size_t>(n / kMinChunk, 1, std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::vector<VoxelChange>> parts(chunks);
  {
    std::vector<std::jthread> helpers;
    helpers.reserve(chunks - 1);
    for (size_t c = 1; c < chunks; ++c)
      helpers.emplace_back([&, c] { parts[c] = changes_in(voxels, n * c / chunks, n * (c + 1) / chunks, tree); });
    parts[0] = changes_in(voxels, 0, n / chunks, tree);
  }  // helpers joined
  std::lock_guard lock(mutex_);
  for (const std::vector<VoxelChange>& part : parts) pending_.insert(pending_.end(), part.begin(), part.end());
  to_version_ = version;
  pending_scans_++;
}

void DeltaPublisher::replaced(const octomap::OcTree&, uint64_t version) {
  std::lock_guard lock(mutex_);
  pending_.clear();
  pending_scans_ = 0;
  from_version_ = to_version_ = version;
  skip_seqs_++;
}

DeltaStats DeltaPublisher::stats() const {
  std::lock_guard lock(mutex_);
  DeltaStats s = stats_;
  s.last_seq = last_seq_;
  return s;
}

void DeltaPublisher::run() {
  const auto period = std::chrono::duration<double>(1.0 / std::max(cfg_.max_rate_hz, 1e-3));
  std::unique_lock lock(mutex_);
  while (!stop_) {
    cv_.wait_for(lock, period, [&] { return stop_; });
    lock.unlock();
    try {
      flush();
    } catch (const std::exception& e) {
      log_ << "octomap-rt-server: map delta failed: " << e.what() << "\n";
    }
    lock.lock();
  }
}

void DeltaPublisher::flush() {
  std::vector<VoxelChange> set;
  uint64_t from, to;
  int64_t scans;
  {
    std::lock_guard lock(mutex_);
    if (pending_.empty() && skip_seqs_ == 0) return;  // versions keep accumulating into the next set
    set.swap(pending_);
    from = from_version_;
    to = to_version_;
    from_version_ = to;
    scans = pending_scans_;
    pending_scans_ = 0;
    next_seq_ += skip_seqs_;
    skip_seqs_ = 0;
  }
  // In the order the scans were applied: after a stable sort by key, the last of each key's
  // run is its newest value.
  std::stable_sort(set.begin(), set.end(), [](const VoxelChange& a, const VoxelChange& b) { return a.key < b.key; });
  size_t kept = 0;
  for (size_t i = 0; i < set.size(); ++i)
    if (i + 1 == set.size() || set[i + 1].key != set[i].key) set[kept++] = set[i];
  set.resize(kept);
  const int8_t mode = cfg_.exact ? Delta::MODE_LOG_ODDS : Delta::MODE_CLASS;
  auto parts = protocol::encode_delta_parts(set, mode, std::max(cfg_.zstd_level, 1), protocol::kDeltaDataBytes);
  if (parts.empty())  // after replaced(): one empty set carries the gap to the mirrors
    parts.push_back(protocol::DeltaPart{0, 0, protocol::zstd_compress("", 1)});
  Delta d{};
  d.from_version = static_cast<int64_t>(from);
  d.to_version = static_cast<int64_t>(to);
  d.snapshot_id = latest_snapshot_id_ ? latest_snapshot_id_() : -1;
  d.num_parts = static_cast<int32_t>(parts.size());
  d.mode = mode;
  d.compression = octomap_rt::map_chunk_t::COMPRESSION_ZSTD;
  d.resolution = cfg_.resolution;
  d.server_id = cfg_.server_id;
  int64_t bytes = 0;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(cfg_.part_interval_ms));
    d.utime = utime_now();
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
