// A spilled region's life away from the tree (octree/region_residency.h).
// Background writes (start_background_writes): eviction detaches a region's nodes on the
// caller's thread, the writer thread encodes and stores them, and the caller lets them go (or
// puts them back, when the store refused) later.
// Steps owed (owe, drop): sweeps over spilled regions without bringing them back; a region
// keeps the steps it owes and applies them, in order, when it comes back. Why this is the map
// without the bound: a sweep's step on a region reads and changes only that region's subtree
// (decay and clearing are per leaf; the prune a step makes is inside it), so applying it later,
// to the same subtree, gives the same subtree; what the sweep did above the region (values,
// prunes, nodes left empty) is done again once the region is back. Meanwhile nothing reads
// the region (anything that does brings it back first).
#include <algorithm>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/clock.h"
#include "octree/region_codec.h"
#include "octree/region_residency.h"

namespace ort {
namespace {

unsigned child_index_at(const octomap::OcTreeKey& key, unsigned depth) {
  const unsigned bit = 15 - depth;
  return ((key[0] >> bit) & 1) | ((key[1] >> bit) & 1) << 1 | ((key[2] >> bit) & 1) << 2;
}

// A child of `node` (at the depth above the region depth) that is still a stand-in.
bool has_stand_in_child(const octomap::OcTree& tree, const RegionGrid& grid, const octomap::OcTreeNode* node,
                        const octomap::OcTreeKey& min_key, unsigned depth,
                        const std::function<bool(RegionId)>& stand_in) {
  if (depth + 1 != grid.depth || !stand_in) return false;
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i) || tree.nodeHasChildren(tree.getNodeChild(node, i))) continue;
    if (stand_in(region_of(grid, child_min_key(min_key, depth, i)))) return true;
  }
  return false;
}

}  // namespace

void apply_owed_steps(octomap::OcTree& tree, const RegionGrid& grid, RegionId id,
                      std::span<const std::shared_ptr<const RegionStep>> steps,
                      const std::function<bool(RegionId)>& stand_in) {
  const octomap::OcTreeKey key = region_min_key(grid, id);
  octomap::OcTreeNode* path[17];
  octomap::OcTreeKey keys[17];
  unsigned index[17];
  path[0] = tree.getRoot();
  keys[0] = octomap::OcTreeKey(0, 0, 0);
  if (path[0] == nullptr) return;
  for (unsigned d = 0; d < grid.depth; ++d) {
    const unsigned i = child_index_at(key, d);
    if (!tree.nodeHasChildren(path[d]) || !tree.nodeChildExists(path[d], i))
      throw std::logic_error("region " + std::to_string(id) + " owes steps but is not in the tree");
    index[d + 1] = i;
    path[d + 1] = tree.getNodeChild(path[d], i);
    keys[d + 1] = child_min_key(keys[d], d, i);
  }
  bool gone = false;
  for (const auto& step : steps)
    if ((gone = (*step)(tree, path[grid.depth], grid.depth, key))) break;
  unsigned depth = grid.depth;
  if (gone) {  // the region goes, and every ancestor it leaves without children
    for (;;) {
      delete_subtree(tree, path[depth - 1], index[depth]);
      --depth;
      if (tree.nodeHasChildren(path[depth])) break;
      free_empty_child_array(path[depth]);
      if (depth == 0) {
        tree.clear();  // nothing left: an empty tree, as OctoMap's after clear()
        return;
      }
    }
  }
  // The nodes above: values from their children, and OctoMap's prune (every node but the root).
  for (unsigned d = gone ? depth + 1 : depth; d-- > 0;) {
    path[d]->updateOccupancyChildren();
    if (d > 0 && !has_stand_in_child(tree, grid, path[d], keys[d], d, stand_in)) tree.pruneNode(path[d]);
  }
}

SweepSpill RegionResidency::sweep_hooks(const RegionGrid& sweep) {
  SweepSpill s;
  auto inside = [this, sweep](RegionId id) { return spilled_in(region_min_key(sweep, id), region_max_key(sweep, id)); };
  s.bring_back = [this, inside](octomap::OcTree& t, RegionId id) {
    for (RegionId r : inside(id)) bring_back(t, r);  // throws when the store refuses: the sweep stops
  };
  s.reshaped = [this](const octomap::OcTreeKey& min_key, unsigned depth) {
    const auto last = static_cast<uint16_t>((1u << (16 - depth)) - 1);
    changed_box(min_key, octomap::OcTreeKey(uint16_t(min_key[0] | last), uint16_t(min_key[1] | last),
                                            uint16_t(min_key[2] | last)));
  };
  s.spilled = [inside](RegionId id) { return !inside(id).empty(); };
  s.depth = grid_.depth;
  s.can_owe = [this, inside](RegionId id) {
    for (RegionId r : inside(id))
      if (!can_owe(r)) return false;
    return true;
  };
  s.stand_in = [this](RegionId id) { return spilled(id); };
  s.owe = [this](RegionId id, const std::shared_ptr<const RegionStep>& step) { owe(id, step); };
  s.drop = [this](RegionId id) { drop(id); };
  return s;
}

bool RegionResidency::can_owe(RegionId id) const {
  const auto it = owed_.find(id);
  return it == owed_.end() || it->second.size() < kMaxOwed;
}

void RegionResidency::owe(RegionId id, std::shared_ptr<const RegionStep> step) {
  if (!spilled(id)) throw std::logic_error("region " + std::to_string(id) + " is owed a step but is not spilled");
  owed_[id].push_back(std::move(step));
  owed_now_++;
  stats_.steps_owed++;
}

std::vector<std::shared_ptr<const RegionStep>> RegionResidency::owed_steps(RegionId id) const {
  const auto it = owed_.find(id);
  return it == owed_.end() ? std::vector<std::shared_ptr<const RegionStep>>{} : it->second;
}

void RegionResidency::apply_owed(octomap::OcTree& tree, RegionId id) {
  const auto it = owed_.find(id);
  if (it == owed_.end()) return;  // nothing happened to it: the tree above is as it was
  const std::vector<std::shared_ptr<const RegionStep>> steps = std::move(it->second);
  owed_.erase(it);
  owed_now_ -= steps.size();
  // The region and its siblings may be reshaped or deleted (a prune of their parent).
  const octomap::OcTreeKey parent = region_min_key(grid_, id & ~RegionId(0x0000'0001'0001'0001ull));
  const auto last = static_cast<uint16_t>(2 * grid_.side_keys() - 1);
  tally_.changed_box(
      parent, octomap::OcTreeKey(uint16_t(parent[0] | last), uint16_t(parent[1] | last), uint16_t(parent[2] | last)));
  apply_owed_steps(tree, grid_, id, steps, [this](RegionId r) { return spilled(r); });
}

void RegionResidency::drop(RegionId id) {
  const auto it = spilled_.find(id);
  if (it == spilled_.end()) return;
  bool in_store = true;
  if (background_) {
    std::unique_lock lock(write_mutex_);
    auto p = pending_.find(id);
    if (p != pending_.end()) {
      if (p->second.state == Pending::State::kWriting) {
        const auto t0 = SteadyClock::now();
        written_.wait(lock, [&] { return pending_.at(id).state != Pending::State::kWriting; });
        stats_.costs.write_wait_ms += ms_since(t0);
        p = pending_.find(id);
      }
      Pending gone = std::move(p->second);
      pending_.erase(p);
      pending_nodes_ -= gone.nodes.nodes;
      if (gone.state == Pending::State::kWritten || gone.state == Pending::State::kFailed) --writes_done_;
      lock.unlock();  // a queued id left in queue_ is skipped by the writer
      in_store = gone.state == Pending::State::kWritten;
      let_go(gone.nodes);
    } else {
      stats_.evicted_bytes -= it->second;
    }
  } else {
    stats_.evicted_bytes -= it->second;
  }
  if (in_store) {
    std::lock_guard spill(spill_mutex_);
    spill_.erase(id);
  }
  spilled_.erase(it);
  if (const auto o = owed_.find(id); o != owed_.end()) {
    owed_now_ -= o->second.size();
    owed_.erase(o);
  }
  last_touch_.erase(id);
  working_set_.forget(id);
  tally_.changed(id);
  stats_.dropped++;
}

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
    apply_owed(tree, id);
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

uint64_t RegionResidency::detach_for_writer(octomap::OcTree& tree, RegionId id, bool may_wait) {
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
      if (!room && writes_done_ == 0 && !may_wait) return 0;
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
