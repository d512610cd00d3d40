#include "daemon/map/map_replica.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <shared_mutex>
#include <span>
#include <thread>

#include "core/clock.h"
#include "core/thread_priority.h"

namespace ort::daemon {

MapReplica::MapReplica(MapState& map, const OctreeUpdateOptions& octree, uint64_t max_pending_bytes,
                       uint64_t max_batch_voxels, int nice, std::optional<RegionGrid> version_grid, bool version_cells,
                       double max_batch_ms, uint64_t rebuild_slice_nodes)
    : record_(map),
      stage_(octree),
      max_pending_bytes_(max_pending_bytes),
      max_batch_voxels_(max_batch_voxels),
      max_batch_ms_(max_batch_ms),
      rebuild_slice_nodes_(rebuild_slice_nodes),
      has_versions_(version_grid.has_value()),
      version_cells_(version_cells),
      builder_(version_grid.value_or(region_grid(11)), version_cells),
      version_threads_(octree.threads != 0 ? octree.threads : std::max(1u, std::thread::hardware_concurrency())) {
  state_.mutex.prefer_writers();  // readers overlap one another: the writer must get in between
  state_.tree = std::make_unique<octomap::OcTree>(*map.tree);
  state_.version = map.version;
  state_.epoch = map.epoch;
  state_.scans = map.scans;
  state_.last_scan_utime = map.last_scan_utime;
  state_.newest_scan = map.newest_scan;
  state_.leaves.store(map.leaves.load(std::memory_order_relaxed), std::memory_order_relaxed);
  stats_.version = map.version;
  stats_.version_depth = has_versions_ ? version_grid->depth : 0;
  record_version_ = applied_version_ = map.version;
  thread_ = std::thread([this, nice] {
    lower_this_thread_priority(nice);
    run();
  });
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
  it.bytes = scan_bytes(voxels.size());
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

void MapReplica::wait_room_locked(std::unique_lock<std::mutex>& lock, uint64_t bytes) {
  // Room for it, unless the queue is empty (one item always fits: the bound never stops the map).
  if (queue_.empty() || stats_.pending_bytes + bytes <= max_pending_bytes_) return;
  const auto t0 = SteadyClock::now();
  stats_.writer_waits++;
  room_.wait(lock, [&] { return stop_ || queue_.empty() || stats_.pending_bytes + bytes <= max_pending_bytes_; });
  stats_.writer_waited_ms += ms_since(t0);
}

void MapReplica::wait_for_room(size_t voxels) {
  if (rebuild_slice_nodes_ > 0) return;  // it falls behind instead
  std::unique_lock lock(mutex_);
  wait_room_locked(lock, scan_bytes(voxels));
}

void MapReplica::push(Item item) {
  std::unique_lock lock(mutex_);
  if (rebuild_slice_nodes_ == 0) wait_room_locked(lock, item.bytes);  // the rule without rebuilds
  record_version_.store(item.version, std::memory_order_release);
  if (behind_) {
    mark_dirty_locked(item);
    return;  // one scan's list, freed by stage 2 (a backlog's lists go to the replica's thread)
  }
  // One item always fits (an empty queue): the replica falls behind only with a backlog, and
  // only under the rule with rebuilds (without it, the wait above returns past the bound only
  // when the replica stops, and the item is queued as before).
  if (rebuild_slice_nodes_ > 0 && !queue_.empty() && stats_.pending_bytes + item.bytes > max_pending_bytes_)
    return fall_behind_locked(std::move(item));
  stats_.pending_items++;
  stats_.pending_bytes += item.bytes;
  stats_.max_pending_bytes_seen = std::max(stats_.max_pending_bytes_seen, stats_.pending_bytes);
  queue_.push_back(std::move(item));
  work_.notify_one();
}

void MapReplica::take_batch(std::deque<Item>& batch) {
  batch.push_back(std::move(queue_.front()));
  queue_.pop_front();
  if (batch.front().whole()) return;
  uint64_t voxels = batch.front().voxels.size();
  uint64_t limit = max_batch_voxels_;
  if (max_batch_ms_ > 0)  // without an estimate yet, one scan
    limit = std::min<uint64_t>(limit, ms_per_voxel_ > 0 ? uint64_t(max_batch_ms_ / ms_per_voxel_) : 0);
  while (!queue_.empty() && !queue_.front().whole() && voxels + queue_.front().voxels.size() <= max_batch_voxels_) {
    if (voxels + queue_.front().voxels.size() > limit) {
      stats_.batches_cut_by_time++;
      break;
    }
    voxels += queue_.front().voxels.size();
    batch.push_back(std::move(queue_.front()));
    queue_.pop_front();
  }
}

double MapReplica::apply_batch(std::deque<Item>& batch, bool log_changes, std::unique_ptr<octomap::OcTree>& retired) {
  std::span<const VoxelUpdate> voxels = batch.front().voxels;
  if (batch.size() > 1) {
    joined_.clear();
    for (const Item& it : batch) joined_.insert(joined_.end(), it.voxels.begin(), it.voxels.end());
    voxels = joined_;
  }
  const auto t0 = SteadyClock::now();
  std::unique_lock lock(state_.mutex);
  const double waited = ms_since(t0);
  const MapHoldNote note(state_.holders, "replica update");
  // The leaf count as the map of record keeps it (daemon/map/map_identity.h): the octree
  // stage says how the batch changed it; a step does not (0 if it left the tree empty).
  std::optional<int64_t> leaf_change;
  if (Item& front = batch.front(); front.tree) {  // a rebuild: the map of record's tree and state then
    retired = std::move(state_.tree);
    state_.tree = std::move(front.tree);
    state_.newest_scan = std::move(front.newest_all);
    state_.leaves.store(front.leaves, std::memory_order_relaxed);
  } else {
    if (front.step)
      front.step(*state_.tree);
    else
      leaf_change = stage_.apply(*state_.tree, voxels, log_changes ? &changes_ : nullptr);
    const int64_t leaves = state_.leaves.load(std::memory_order_relaxed);
    state_.leaves.store(!state_.tree->getRoot()      ? 0
                        : leaves >= 0 && leaf_change ? leaves + *leaf_change
                                                     : -1,
                        std::memory_order_relaxed);
  }
  for (Item& it : batch)
    if (!it.robot.empty()) state_.newest_scan[it.robot] = std::move(it.newest);
  const Item& last = batch.back();
  state_.version = last.version;
  state_.epoch = last.epoch;
  state_.scans = last.scans;
  state_.last_scan_utime = last.last_scan_utime;
  return waited;
}

void MapReplica::run() {
  std::deque<Item> batch;
  // Versions take at most a third of this thread's time (after one that took t, the next comes
  // 2t later at the earliest), so that it keeps up where scans touch most regions between two
  // versions; readers wait for theirs meanwhile, off every lock.
  SteadyClock::time_point next_version_at{}, next_slice_at{};
  std::deque<Item> dropped;
  std::unique_ptr<octomap::OcTree> retired;
  for (;;) {
    bool note_regions = false;
    uint64_t drops = 0;
    dropped.clear();  // what push dropped or did not queue: freed here, outside both locks
    retired.reset();
    {
      std::unique_lock lock(mutex_);
      dropped.swap(dropped_);
      // A rebuild's slices take at most half this thread's time (after one that held the map of
      // record for t, the next comes t later at the earliest), so that stage 2 gets the lock
      // between them (the map of record's lock prefers readers).
      auto slice_due = [&] { return behind_ && queue_.empty() && SteadyClock::now() >= next_slice_at; };
      // A reader waiting for a version the tree has reached goes before the next batch.
      auto version_wanted = [&] { return wanted_ && stats_.version >= wanted_version_; };
      auto version_due = [&] { return version_wanted() && SteadyClock::now() >= next_version_at; };
      const auto idle_from = SteadyClock::now();
      while (!stop_ && queue_.empty() && !version_due() && !slice_due()) {
        if (behind_ && (!version_wanted() || next_slice_at < next_version_at))
          work_.wait_until(lock, next_slice_at);
        else if (version_wanted())
          work_.wait_until(lock, next_version_at);
        else
          work_.wait(lock);
      }
      stats_.idle_ms_total += ms_since(idle_from);
      if (version_due()) {
        wanted_ = false;
        lock.unlock();
        const auto t0 = SteadyClock::now();
        make_version();
        const auto t1 = SteadyClock::now();
        next_version_at = t1 + 2 * (t1 - t0);
        continue;
      }
      if (stop_) {
        // What is still queued is left: the server stops the replica once its drain deadline
        // passed, and applying a backlog of big scans at this thread's low priority took
        // minutes on a loaded machine. From here readers read the map of record
        // (readable_map, read_version) unless the replica had caught up.
        exited_ = true;
        progress_.notify_all();
        return;
      }
      if (queue_.empty()) {  // behind: a slice of the rebuild
        lock.unlock();
        const double held_ms = rebuild_slice();
        next_slice_at = SteadyClock::now() + std::chrono::microseconds(int64_t(held_ms * 1e3));
        continue;
      }
      take_batch(batch);
      note_regions = versions_on_;
      drops = drops_;
    }
    const auto t0 = SteadyClock::now();
    const double waited = apply_batch(batch, note_regions && version_cells_, retired);
    const double applied_ms = ms_since(t0);
    double note_ms = 0;
    if (note_regions) {  // what the next version writes again: the regions of the leaves that changed
      const auto n0 = SteadyClock::now();
      std::lock_guard build(build_mutex_);
      if (batch.front().whole())
        builder_.changed_all();
      else if (version_cells_)
        builder_.changed(changes_);
      else
        for (const Item& it : batch) builder_.changed(it.voxels);
      note_ms = ms_since(n0);
    }
    uint64_t bytes = 0, voxels = 0;
    for (const Item& it : batch) {
      bytes += it.bytes;
      voxels += it.voxels.size();
    }
    if (!batch.front().whole() && voxels > 0) {  // the estimate take_batch's time bound uses: recent updates weigh most
      const double sample = (applied_ms - std::min(applied_ms, waited)) / double(voxels);
      ms_per_voxel_ = ms_per_voxel_ > 0 ? 0.7 * ms_per_voxel_ + 0.3 * sample : sample;
    }
    const uint64_t items = batch.size();
    batch.clear();  // the voxel lists are freed outside both locks
    {
      std::lock_guard lock(mutex_);
      stats_.apply_ms_total += applied_ms - std::min(applied_ms, waited);
      stats_.lock_wait_ms_total += waited;
      stats_.version_note_ms_total += note_ms;
      stats_.lock_wait_ms_max = std::max(stats_.lock_wait_ms_max, waited);
      stats_.updates++;
      if (items > 1) stats_.scans_in_batches += items;
      stats_.largest_batch = std::max(stats_.largest_batch, items);
      stats_.ms_per_voxel = ms_per_voxel_;
      if (drops == drops_) {  // else push dropped the queue it was counted in
        stats_.pending_items -= std::min(stats_.pending_items, items);
        stats_.pending_bytes -= std::min(stats_.pending_bytes, bytes);
      }
      stats_.version = state_.version;
      applied_version_.store(state_.version, std::memory_order_release);
    }
    room_.notify_all();
    progress_.notify_all();
    state_.changed.notify_all();
  }
}

void MapReplica::make_version() {
  // Only the replica's thread changes the tree (and, once it exited, nothing does): it is
  // read here without its lock, while query turns read it under theirs.
  std::lock_guard build(build_mutex_);
  const auto t0 = SteadyClock::now();
  const int64_t cpu0 = thread_cpu_ns();
  auto v = std::make_shared<ReplicaVersion>();
  // (Without cells, as before them: on this thread alone.)
  if (!version_pool_ && version_threads_ > 1 && version_cells_)
    version_pool_ = std::make_unique<WorkerPool>(version_threads_, false, 19);
  v->map = builder_.build(*state_.tree, version_pool_.get());
  v->version = state_.version;
  v->epoch = state_.epoch;
  v->scans = state_.scans;
  v->last_scan_utime = state_.last_scan_utime;
  v->newest_scan = state_.newest_scan;
  const double ms = ms_since(t0), cpu_ms = double(thread_cpu_ns() - cpu0) / 1e6;
  const auto figures = builder_.last_build();
  const uint64_t v_bytes = v->map->data_bytes();
  {
    std::lock_guard lock(mutex_);
    if (!latest_ || latest_->version <= v->version) latest_ = std::move(v);
    stats_.versions_built++;
    stats_.version_ms_total += ms;
    stats_.version_ms_max = std::max(stats_.version_ms_max, ms);
    stats_.version_regions = figures.regions;
    stats_.version_regions_written = figures.regions_written;
    stats_.version_bytes = v_bytes;
    stats_.version_bytes_written = figures.bytes_written;
    if (stats_.versions_built > 1) {
      stats_.version_bytes_written_later += figures.bytes_written;
      stats_.version_nodes_written_later += figures.nodes_written;
      stats_.version_nodes_copied_later += figures.nodes_copied;
      stats_.version_ms_later += ms;
      stats_.version_cpu_ms_later += cpu_ms;
    }
  }
  progress_.notify_all();
}

std::shared_ptr<const ReplicaVersion> MapReplica::read_version(uint64_t min_version) {
  std::unique_lock lock(mutex_);
  versions_on_ = true;
  for (;;) {
    if (latest_ && latest_->version >= min_version) return latest_;
    if (behind_) return nullptr;         // the reader copies the map of record until the rebuild caught up
    if (exited_) {                       // nothing changes the tree any more: the reader makes the version itself
      if (!caught_up()) return nullptr;  // it stopped behind the map of record
      lock.unlock();
      make_version();
      lock.lock();
      return latest_;
    }
    wanted_ = true;
    wanted_version_ = std::max(wanted_version_, min_version);
    work_.notify_one();
    progress_.wait(lock);
  }
}

bool MapReplica::wait_for(uint64_t version, double timeout_s) {
  std::unique_lock lock(mutex_);
  return progress_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                            [&] { return stop_ || behind_ || stats_.version >= version; });
}

bool MapReplica::stopped_behind() const {
  std::lock_guard lock(mutex_);
  return stop_ && !caught_up();
}

bool MapReplica::reads_record() const {
  std::lock_guard lock(mutex_);
  return behind_ || (stop_ && !caught_up());
}

ReplicaStats MapReplica::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

MapState& readable_map(MapState& map) {
  if (!map.replica) return map;
  // The map of record's id without its lock: a reader never holds the octree stage up.
  map.replica->wait_for(map.replica->record_version(), 1e9);
  return map.replica->reads_record() ? map : map.replica->state();
}

std::shared_ptr<const ReplicaVersion> readable_version(MapState& map) {
  if (!map.replica || !map.replica->has_versions()) return nullptr;
  return map.replica->read_version(map.replica->record_version());
}

MapState* lock_for_short_read(MapState& map, uint64_t min_version, std::shared_lock<MapMutex>& lock) {
  if (!map.replica) {
    lock = std::shared_lock(map.mutex);
    return &map;
  }
  MapState& replica = map.replica->state();
  auto try_replica = [&] {
    lock = std::shared_lock(replica.mutex, std::try_to_lock);
    if (lock.owns_lock() && replica.version >= min_version) return true;
    if (lock.owns_lock()) lock.unlock();
    return false;
  };
  // A replica that caught up is the map of record's state: read it, and leave the map of
  // record's lock to stage 2 (every reader that takes it may hold stage 2 up).
  if (map.replica->caught_up() && try_replica()) return &replica;
  // Else whichever is free now. Never wait for one while holding the other: a rebuild's slice
  // holds the map of record (shared) and may wait for nothing else, but the replica's thread
  // waits for the replica's lock.
  lock = std::shared_lock(map.mutex, std::try_to_lock);
  if (lock.owns_lock()) return &map;
  if (try_replica()) return &replica;
  return nullptr;
}

}  // namespace ort::daemon
