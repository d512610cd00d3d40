#include "daemon/map/map_replica.h"

#include <algorithm>
#include <chrono>
#include <shared_mutex>

#include "core/clock.h"

namespace ort::daemon {

MapReplica::MapReplica(const MapState& map, const OctreeUpdateOptions& octree, uint64_t max_pending_bytes)
    : stage_(octree), max_pending_bytes_(max_pending_bytes) {
  state_.tree = std::make_unique<octomap::OcTree>(*map.tree);
  state_.version = map.version;
  state_.epoch = map.epoch;
  state_.scans = map.scans;
  state_.last_scan_utime = map.last_scan_utime;
  state_.newest_scan = map.newest_scan;
  stats_.version = map.version;
  thread_ = std::thread([this] { run(); });
}

MapReplica::~MapReplica() { stop(); }

void MapReplica::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  room_.notify_all();
  progress_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void MapReplica::scan_applied(VoxelList& voxels, const MapState& map, const std::string& robot_lower) {
  Item it;
  it.bytes = voxels.size() * sizeof(VoxelUpdate) + sizeof(Item);
  it.voxels.swap(voxels);
  it.version = map.version;
  it.epoch = map.epoch;
  it.scans = map.scans;
  it.last_scan_utime = map.last_scan_utime;
  it.robot = robot_lower;
  it.newest = map.newest_scan.at(robot_lower);
  push(std::move(it));
}

void MapReplica::step_applied(MapStep step, const MapState& map) {
  Item it;
  it.step = std::move(step);
  it.bytes = sizeof(Item);
  it.version = map.version;
  it.epoch = map.epoch;
  it.scans = map.scans;
  it.last_scan_utime = map.last_scan_utime;
  push(std::move(it));
}

void MapReplica::push(Item item) {
  std::unique_lock lock(mutex_);
  // Room for it, unless the queue is empty (one item always fits: the bound never stops the map).
  if (!queue_.empty() && stats_.pending_bytes + item.bytes > max_pending_bytes_) {
    const auto t0 = SteadyClock::now();
    room_.wait(lock,
               [&] { return stop_ || queue_.empty() || stats_.pending_bytes + item.bytes <= max_pending_bytes_; });
    stats_.writer_waited_ms += ms_since(t0);
  }
  stats_.pending_items++;
  stats_.pending_bytes += item.bytes;
  stats_.max_pending_bytes_seen = std::max(stats_.max_pending_bytes_seen, stats_.pending_bytes);
  queue_.push_back(std::move(item));
  work_.notify_one();
}

void MapReplica::run() {
  for (;;) {
    Item it;
    {
      std::unique_lock lock(mutex_);
      work_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopped with nothing left
      it = std::move(queue_.front());
      queue_.pop_front();
    }
    const auto t0 = SteadyClock::now();
    {
      std::unique_lock lock(state_.mutex);
      if (it.step)
        it.step(*state_.tree);
      else
        stage_.apply(*state_.tree, it.voxels);
      state_.version = it.version;
      state_.epoch = it.epoch;
      state_.scans = it.scans;
      state_.last_scan_utime = it.last_scan_utime;
      if (!it.robot.empty()) state_.newest_scan[it.robot] = std::move(it.newest);
    }
    const uint64_t bytes = it.bytes;
    it = Item{};  // the voxel list is freed outside both locks
    {
      std::lock_guard lock(mutex_);
      stats_.apply_ms_total += ms_since(t0);
      stats_.pending_items--;
      stats_.pending_bytes -= std::min(stats_.pending_bytes, bytes);
      stats_.version = state_.version;
    }
    room_.notify_all();
    progress_.notify_all();
    state_.changed.notify_all();
  }
}

bool MapReplica::wait_for(uint64_t version, double timeout_s) {
  std::unique_lock lock(mutex_);
  return progress_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                            [&] { return stop_ || stats_.version >= version; });
}

ReplicaStats MapReplica::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

MapState& readable_map(MapState& map) {
  if (!map.replica) return map;
  uint64_t version;
  {
    std::shared_lock lock(map.mutex);
    version = map.version;
  }
  map.replica->wait_for(version, 1e9);
  return map.replica->state();
}

}  // namespace ort::daemon
