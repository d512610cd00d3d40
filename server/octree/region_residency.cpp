#include "octree/region_residency.h"

#include <algorithm>
#include <unordered_set>

#include "core/clock.h"
#include "octree/region_codec.h"

namespace ort {

RegionResidency::RegionResidency(const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes)
    : grid_(grid), spill_(spill), max_bytes_(max_bytes), tally_(grid) {}

RegionResidency::~RegionResidency() {
  stop_writer();
  for (auto& [id, p] : pending_) free_detached(p.nodes);  // the tree holds stand-ins only: nothing refers to them
}

void RegionResidency::restore(octomap::OcTree& tree, RegionId id) {
  auto it = spilled_.find(id);
  if (it == spilled_.end()) return;
  const auto t0 = SteadyClock::now();
  if (background_) {
    std::unique_lock lock(write_mutex_);
    auto p = pending_.find(id);
    if (p != pending_.end()) {
      if (p->second.state == Pending::State::kWriting) {
        written_.wait(lock, [&] { return pending_.at(id).state != Pending::State::kWriting; });
        stats_.costs.write_wait_ms += ms_since(t0);
        p = pending_.find(id);
      }
      Pending back = std::move(p->second);
      pending_.erase(p);
      pending_nodes_ -= back.nodes.nodes;
      if (back.state == Pending::State::kWritten || back.state == Pending::State::kFailed) --writes_done_;
      lock.unlock();  // a queued id left in queue_ is skipped by the writer
      tally_.changed(id);
      reattach_region(tree, grid_, id, back.nodes);
      if (back.state == Pending::State::kWritten) {
        std::lock_guard spill(spill_mutex_);
        spill_.erase(id);
      }
      spilled_.erase(it);
      apply_owed(tree, id);
      stats_.costs.rebuild_ms += ms_since(t0);
      stats_.costs.reattached++;
      stats_.restores++;
      return;
    }
  }
  std::vector<uint8_t> bytes;
  {
    std::lock_guard spill(spill_mutex_);
    bytes = spill_.get(id);
  }
  const auto t1 = SteadyClock::now();
  tally_.changed(id);
  restore_region(tree, grid_, id, bytes);
  stats_.costs.get_ms += ms_between(t0, t1);
  stats_.costs.rebuild_ms += ms_since(t1);
  stats_.evicted_bytes -= it->second;
  spilled_.erase(it);
  {
    std::lock_guard spill(spill_mutex_);
    spill_.erase(id);
  }
  apply_owed(tree, id);
  stats_.restores++;
}

void RegionResidency::touch(octomap::OcTree& tree, std::span<const RegionId> ids) {
  ++tick_;
  const WorkingSetWindow::TimePoint now = working_set_.now();
  for (RegionId id : ids) {
    last_touch_[id] = tick_;
    working_set_.touch(id, now);
    tally_.changed(id);  // about to be read or changed
    if (spilled_.empty()) continue;
    // The region and its parent's other children (region_residency.h says why).
    const octomap::OcTreeKey k = region_min_key(grid_, id);
    const unsigned side = grid_.side_keys();
    for (unsigned i = 0; i < 8; ++i) {
      octomap::OcTreeKey s = k;
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned parent_min = k[a] & ~(2 * side - 1);
        s[a] = static_cast<uint16_t>(parent_min + ((i >> a) & 1) * side);
      }
      restore(tree, region_of(grid_, s));
    }
  }
}

void RegionResidency::touch_voxels(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels) {
  std::vector<RegionId> ids;
  RegionId last = ~RegionId(0);
  for (const VoxelUpdate& v : voxels) {
    const RegionId id = region_of(grid_, v.key());
    if (id != last) ids.push_back(id);
    last = id;
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  touch(tree, ids);
}

namespace {

// The id shared by the eight children of one node above the region depth: the region
// coordinates with their lowest bit cleared (ids pack 16 bits an axis: octree/region.h).
RegionId sibling_group(RegionId id) { return id & ~RegionId(0x0000'0001'0001'0001ull); }

// Inner nodes of an encoded region (octree/region_codec.h: 5 bytes a node, the last its
// child bits): each had a child array, freed with the nodes below the stand-in.
uint64_t inner_nodes(const std::vector<uint8_t>& encoded) {
  constexpr size_t kHeader = 36, kNode = 5;
  uint64_t n = 0;
  for (size_t at = kHeader; at + kNode <= encoded.size(); at += kNode) n += encoded[at + 4] != 0;
  return n;
}

}  // namespace

size_t RegionResidency::enforce(octomap::OcTree& tree) { return enforce(tree, memory(tree), max_bytes_).regions; }

EnforceResult RegionResidency::enforce(octomap::OcTree& tree, uint64_t bytes, uint64_t target, size_t max_groups,
                                       double budget_ms, bool idle_only) {
  EnforceResult result;
  const auto start = SteadyClock::now();
  std::string write_error;  // a background put that failed: thrown after this pass
  if (background_) {
    try {
      collect_writes(tree);
    } catch (const std::exception& e) {
      write_error = e.what();
    }
  }
  if (bytes <= target) {
    if (!write_error.empty()) throw std::runtime_error(write_error);
    return result;
  }
  // Siblings go together, as the group's most recent touch: a touch brings a region's seven
  // siblings back with it (region_residency.h), so a sibling spilled alone would come back at
  // the next touch of its neighbour and go again at the next enforce.
  struct Candidate {
    uint64_t touched;
    RegionId group, id;
  };
  struct GroupTouch {
    uint64_t tick = 0;
    WorkingSetWindow::TimePoint at = WorkingSetWindow::TimePoint::min();
  };
  const auto listing = SteadyClock::now();
  std::vector<Candidate> candidates;
  std::unordered_map<RegionId, GroupTouch> group_touched;
  for_each_region(tree, grid_, [&](RegionId id, const RegionNode& r) {
    if (r.depth != grid_.depth || !tree.nodeHasChildren(r.node)) return;  // coarse leaves, stand-ins
    auto it = last_touch_.find(id);
    const uint64_t touched = it == last_touch_.end() ? 0 : it->second;
    const RegionId group = sibling_group(id);
    GroupTouch& g = group_touched[group];
    g.tick = std::max(g.tick, touched);
    if (idle_only) g.at = std::max(g.at, working_set_.last_touch(id));
    candidates.push_back({touched, group, id});
  });
  for (Candidate& c : candidates) c.touched = group_touched[c.group].tick;
  // One clock reading for the whole pass: a group is idle when its latest touch is at or
  // before it.
  const WorkingSetWindow::TimePoint idle_before = working_set_.idle_before();
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    if (a.touched != b.touched) return a.touched < b.touched;
    return a.group != b.group ? a.group < b.group : a.id < b.id;
  });
  result.listed = candidates.size();
  stats_.costs.list_ms += ms_since(listing);
  size_t groups = 0;
  RegionId group = ~RegionId(0);
  for (const Candidate& c : candidates) {
    if (c.group != group) {  // whole groups only: stop between two
      if (bytes <= target || groups == max_groups) break;
      // Groups are in touch order and the clock never goes back: every later group is in use too.
      if (idle_only && group_touched[c.group].at > idle_before) break;
      // The budget cuts the way from the bound down to `target`, never the way to the bound.
      if (budget_ms > 0 && groups > 0 && bytes <= max_bytes_ && ms_since(start) >= budget_ms) break;
      group = c.group;
      ++groups;
    }
    if (background_) {
      // A refused write put back with owed steps may have reshaped the regions listed.
      const RegionNode r = find_region(tree, grid_, c.id);
      if (r.node == nullptr || r.depth != grid_.depth || !tree.nodeHasChildren(r.node)) continue;
      // Below the bound a pass does not wait for the writer's room: it ends (the rest goes later).
      const uint64_t freed_bytes = detach_for_writer(tree, c.id, bytes > max_bytes_);
      if (freed_bytes == 0) break;
      bytes -= std::min(bytes, freed_bytes);
      result.bytes_freed += freed_bytes;
      result.regions++;
      continue;
    }
    const auto t0 = SteadyClock::now();
    const std::vector<uint8_t> encoded = encode_region(tree, grid_, c.id);
    const auto t1 = SteadyClock::now();
    spill_.put(c.id, encoded);  // durable before the nodes go
    tally_.changed(c.id);
    const auto t2 = SteadyClock::now();
    uint64_t freed = 0;
    if (free_later_) {
      DetachedSubtree d = detach_region(tree, grid_, c.id, read_region_header(encoded).nodes - 1);
      freed = d.nodes;
      free_later_(d);
    } else {
      freed = strip_region(tree, grid_, c.id);
    }
    stats_.costs.encode_ms += ms_between(t0, t1);
    stats_.costs.put_ms += ms_between(t1, t2);
    stats_.costs.strip_ms += ms_since(t2);
    const uint64_t freed_bytes =
        freed * tree.memoryUsageNode() + inner_nodes(encoded) * 8 * sizeof(octomap::OcTreeNode*);
    spilled_[c.id] = encoded.size();
    stats_.evicted_bytes += encoded.size();
    stats_.evictions++;
    bytes -= std::min(bytes, freed_bytes);
    result.bytes_freed += freed_bytes;
    result.regions++;
  }
  if (!write_error.empty()) throw std::runtime_error(write_error);
  return result;
}

std::vector<RegionId> RegionResidency::spilled_in(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi) const {
  std::vector<RegionId> out;
  if (spilled_.empty()) return out;
  const unsigned s = grid_.shift();
  uint64_t cells = 1;
  for (unsigned a = 0; a < 3; ++a) cells *= uint64_t((hi[a] >> s) - (lo[a] >> s) + 1);
  if (cells <= spilled_.size()) {  // few regions in the box: look each up
    for (unsigned z = lo[2] >> s; z <= unsigned(hi[2] >> s); ++z)
      for (unsigned y = lo[1] >> s; y <= unsigned(hi[1] >> s); ++y)
        for (unsigned x = lo[0] >> s; x <= unsigned(hi[0] >> s); ++x) {
          const octomap::OcTreeKey k(uint16_t(x << s), uint16_t(y << s), uint16_t(z << s));
          const RegionId id = region_of(grid_, k);
          if (spilled_.count(id)) out.push_back(id);
        }
  } else {  // a large box: test each spilled region
    for (const auto& [id, b] : spilled_) {
      const octomap::OcTreeKey k = region_min_key(grid_, id);
      bool meets = true;
      for (unsigned a = 0; a < 3; ++a) meets = meets && (k[a] >> s) >= (lo[a] >> s) && (k[a] >> s) <= (hi[a] >> s);
      if (meets) out.push_back(id);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

void RegionResidency::adopt_spilled(RegionId id, std::span<const uint8_t> bytes) {
  {
    std::lock_guard spill(spill_mutex_);
    spill_.put(id, bytes);
  }
  adopt_spilled(id, bytes.size());
}

void RegionResidency::adopt_spilled(RegionId id, uint64_t bytes) {
  tally_.changed(id);
  auto [it, added] = spilled_.emplace(id, bytes);
  if (!added) {
    stats_.evicted_bytes -= it->second;
    it->second = bytes;
  }
  stats_.evicted_bytes += bytes;
}

std::vector<RegionId> RegionResidency::spilled_ids() const {
  std::vector<RegionId> ids;
  for (const auto& [id, b] : spilled_) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

void RegionResidency::forget_all() {
  flush();
  {
    std::lock_guard lock(write_mutex_);  // the tree was emptied: kept nodes are nobody's
    for (auto& [id, p] : pending_) let_go(p.nodes);
    pending_.clear();
    queue_.clear();
    pending_nodes_ = 0;
    writes_done_ = 0;
  }
  std::lock_guard spill(spill_mutex_);
  for (RegionId id : spilled_ids()) spill_.erase(id);
  spilled_.clear();
  owed_.clear();
  owed_now_ = 0;
  stats_.evicted_bytes = 0;
  tally_.changed_all();
}

void RegionResidency::restore_all(octomap::OcTree& tree) {
  for (RegionId id : spilled_ids()) restore(tree, id);
}

ResidencyStats RegionResidency::stats() const {
  ResidencyStats s = stats_;
  s.evicted_regions = spilled_.size();
  s.owed_now = owed_now_;
  std::lock_guard lock(write_mutex_);
  s.costs.encode_ms += writer_encode_ms_;
  s.costs.put_ms += writer_put_ms_;
  return s;
}

}  // namespace ort
