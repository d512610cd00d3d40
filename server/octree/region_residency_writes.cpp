// RegionResidency's background writes (octree/region_residency.h start_background_writes):
// eviction detaches a region's nodes on the caller's thread, the writer thread encodes and
// stores them, and the caller lets them go (or puts them back, when the store refused) later.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/clock.h"
#include "octree/region_codec.h"
#include "octree/region_residency.h"

namespace ort {

void RegionResidency::stop_writer() {
  if (!writer_.joinable()) return;
  {
    std::lock_guard lock(write_mutex_);
    stopping_ = true;
  }
  wake_writer_.notify_all();
  writer_.join();
}

void RegionResidency::start_background_writes(uint64_t max_pending_nodes) {
  if (background_) return;
  background_ = true;
  max_pending_nodes_ = std::max<uint64_t>(1, max_pending_nodes);
  writer_ = std::thread([this] { write_loop(); });
}

uint64_t RegionResidency::pending_nodes() const {
  std::lock_guard lock(write_mutex_);
  return pending_nodes_;
}

void RegionResidency::let_go(DetachedSubtree d) {
  if (free_later_)
    free_later_(d);
  else
    free_detached(d);
}

// The writer: takes the oldest queued region, encodes its kept nodes and puts the bytes, all
// without write_mutex_ (a pending region's nodes change only after it is done with them:
// restore waits for kWriting to end).
void RegionResidency::write_loop() {
  std::unique_lock lock(write_mutex_);
  for (;;) {
    wake_writer_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    const RegionId id = queue_.front();
    queue_.pop_front();
    auto it = pending_.find(id);
    if (it == pending_.end() || it->second.state != Pending::State::kQueued) continue;
    Pending& p = it->second;
    p.state = Pending::State::kWriting;
    const DetachedSubtree nodes = p.nodes;
    const float root = p.root_log_odds;
    lock.unlock();
    std::string error;
    uint64_t bytes = 0;
    const auto t0 = SteadyClock::now();
    double encode_ms = 0;
    try {
      const std::vector<uint8_t> encoded = encode_detached(id, grid_.depth, root, nodes);
      encode_ms = ms_since(t0);
      bytes = encoded.size();
      std::lock_guard spill(spill_mutex_);
      spill_.put(id, encoded);
    } catch (const std::exception& e) {
      error = e.what();
    }
    const double total_ms = ms_since(t0);
    lock.lock();
    writer_encode_ms_ += encode_ms;
    writer_put_ms_ += total_ms - encode_ms;
    Pending& done = pending_.at(id);  // restore and collect wait while kWriting
    done.state = error.empty() ? Pending::State::kWritten : Pending::State::kFailed;
    done.bytes = bytes;
    done.error = std::move(error);
    ++writes_done_;
    written_.notify_all();
  }
}

void RegionResidency::collect_writes(octomap::OcTree& tree) {
  std::vector<std::pair<RegionId, Pending>> done;
  {
    std::lock_guard lock(write_mutex_);
    if (writes_done_ == 0) return;
    for (auto it = pending_.begin(); it != pending_.end();) {
      const Pending::State st = it->second.state;
      if (st == Pending::State::kWritten || st == Pending::State::kFailed) {
        pending_nodes_ -= it->second.nodes.nodes;
        done.emplace_back(it->first, std::move(it->second));
        it = pending_.erase(it);
      } else {
        ++it;
      }
    }
    writes_done_ = 0;
  }
  std::string first_error;
  for (auto& [id, p] : done) {
    if (p.state == Pending::State::kWritten) {
      spilled_[id] = p.bytes;
      stats_.evicted_bytes += p.bytes;
      let_go(p.nodes);
      continue;
    }
    // The store refused: the region is back in the tree as if it had never gone.
    tally_.changed(id);
    reattach_region(tree, grid_, id, p.nodes);
    spilled_.erase(id);
    stats_.evictions--;
    if (first_error.empty()) first_error = "region " + std::to_string(id) + ": " + p.error;
  }
  if (!first_error.empty()) throw std::runtime_error(first_error);
}

void RegionResidency::flush() {
  if (!background_) return;
  const auto t0 = SteadyClock::now();
  std::unique_lock lock(write_mutex_);
  written_.wait(lock, [&] {
    for (const auto& [id, p] : pending_)
      if (p.state == Pending::State::kQueued || p.state == Pending::State::kWriting) return false;
    return true;
  });
  stats_.costs.write_wait_ms += ms_since(t0);
}

std::vector<uint8_t> RegionResidency::spilled_bytes(RegionId id) const {
  {
    std::lock_guard lock(write_mutex_);
    auto it = pending_.find(id);
    // Kept nodes: encoded here (the writer only reads them too; nothing frees them while the
    // caller keeps the tree's writers out, and only those let pending regions go).
    if (it != pending_.end()) return encode_detached(id, grid_.depth, it->second.root_log_odds, it->second.nodes);
  }
  std::lock_guard spill(spill_mutex_);
  return spill_.get(id);
}

uint64_t RegionResidency::detach_for_writer(octomap::OcTree& tree, RegionId id) {
  const auto t0 = SteadyClock::now();
  const SubtreeSize size = region_size(tree, grid_, id);
  const float root = find_region(tree, grid_, id).node->getLogOdds();
  const auto t1 = SteadyClock::now();
  stats_.costs.size_ms += ms_between(t0, t1);
  // Room among the kept nodes: wait for the writer (what it finished is let go here).
  for (;;) {
    bool room = false;
    {
      std::unique_lock lock(write_mutex_);
      room = pending_.empty() || pending_nodes_ + size.nodes_below <= max_pending_nodes_;
      // Not empty and nothing done: the writer has one queued or in hand.
      if (!room && writes_done_ == 0) written_.wait(lock, [&] { return writes_done_ > 0; });
    }
    if (room) break;
    collect_writes(tree);  // throws a failed put's error: this pass ends, the region stays
  }
  stats_.costs.write_wait_ms += ms_since(t1);
  const auto t2 = SteadyClock::now();
  DetachedSubtree d = detach_region(tree, grid_, id, size.nodes_below);
  tally_.changed(id);
  {
    std::lock_guard lock(write_mutex_);
    Pending& p = pending_[id];
    p = Pending{};
    p.nodes = d;
    p.root_log_odds = root;
    pending_nodes_ += d.nodes;
    queue_.push_back(id);
  }
  wake_writer_.notify_one();
  spilled_[id] = 0;  // its bytes count once written (collect_writes)
  stats_.evictions++;
  stats_.costs.strip_ms += ms_since(t2);
  return size.nodes_below * tree.memoryUsageNode() + size.inner * 8 * sizeof(octomap::OcTreeNode*);
}

}  // namespace ort
