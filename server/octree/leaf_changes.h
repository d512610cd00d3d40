// What one octree update changed, leaf by leaf: the optional change log of the octree stage
// (OctreeStage::apply, BatchedOctreeUpdater::apply, apply_updates_sequential).
//
// The batched update visits every finest leaf it changes and knows its value before and
// after, so it writes them down as it goes (one vector per worker thread, no locks) instead
// of a second walk from the root per voxel afterwards. What counts as a change is OctoMap's
// semantics, as a search() of the key before and after the update would see it:
// - a key whose update returns early (its leaf, or the pruned node above it, already at the
//   clamping bound in the update's direction) changes nothing and is not logged;
// - expanding a pruned node copies its value into 8 children, pruning keeps it: the keys
//   below change only when they are updated themselves, and then `before` is the pruned
//   node's value;
// - a key with no node on its path before (the update creates its leaf) is `was_unknown`;
// - a key repeated in one list: the batched update logs it once (the first update's before,
//   the last one's after); the updateNode loop logs it once per update that changed it, in
//   the order applied. Readers that combine several logs keep, per key, the first before and
//   the last after (daemon/delta_changes.h).
// Values, not node pointers: pruning frees leaves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>

#include "octree/batched/morton_order.h"

namespace ort {

struct LeafChange {
  static constexpr uint64_t kUnknownBit = 1ull << 63;
  uint64_t code = 0;  // Morton code of the key (morton_order.h); kUnknownBit: no node covered it before
  float before = 0;   // log-odds before (0 when unknown)
  float after = 0;    // log-odds after

  static LeafChange make(uint64_t morton, bool was_unknown, float before, float after) {
    return LeafChange{morton | (was_unknown ? kUnknownBit : 0), before, after};
  }
  uint64_t morton() const { return code & ~kUnknownBit; }
  bool was_unknown() const { return (code & kUnknownBit) != 0; }
  octomap::OcTreeKey key() const {
    uint16_t x, y, z;
    morton_decode(morton(), x, y, z);
    return octomap::OcTreeKey(x, y, z);
  }
};
static_assert(sizeof(LeafChange) == 16);

// Appends the change of one applied leaf update to a worker's lane: consecutive updates of
// the same key (a key repeated in a sorted bucket) make one change; an update that left the
// value as it was (cannot happen with OctoMap's non-zero hit/miss, kept for safety) none.
inline void log_leaf_change(std::vector<LeafChange>& lane, uint64_t morton, bool was_unknown, float before,
                            float after) {
  if (!lane.empty() && lane.back().morton() == morton) {
    lane.back().after = after;
    return;
  }
  if (was_unknown || after != before) lane.push_back(LeafChange::make(morton, was_unknown, before, after));
}

// The log of one update: per-worker lanes cut into segments, read back in a fixed order
// (the segments' order keys: the batched update's subtrees in Morton order), so the result
// does not depend on which thread took which subtree. Reused from update to update (reset()
// keeps the capacity).
class LeafChanges {
 public:
  void reset(unsigned lanes);
  unsigned lanes() const { return static_cast<unsigned>(lanes_.size()); }
  std::vector<LeafChange>& lane(unsigned i) { return lanes_[i]; }
  // The lane's changes since its last segment become one segment, read back at `order`.
  // Each lane is written by one thread at a time; finish() after all threads are done.
  void close_segment(unsigned lane, size_t order);
  void finish();

  size_t size() const;
  bool empty() const { return size() == 0; }
  template <class F>
  void for_each(F&& f) const {
    for (const Segment& s : segments_)
      for (size_t i = s.begin; i < s.end; ++i) f(lanes_[s.lane][i]);
  }
  std::vector<LeafChange> to_vector() const;

 private:
  struct Segment {
    size_t order;
    unsigned lane;
    size_t begin, end;
  };
  std::vector<std::vector<LeafChange>> lanes_;
  std::vector<std::vector<Segment>> lane_segments_;  // per lane, until finish()
  std::vector<Segment> segments_;                    // all, in order, after finish()
};

}  // namespace ort
