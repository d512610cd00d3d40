#include "octree/versions/region_sync.h"

#include <stdexcept>

namespace ort {
namespace {

using octomap::OcTree;
using octomap::OcTreeKey;
using octomap::OcTreeNode;

// Leaves `n` childless through OctoMap's own calls, so that the tree's node count stays right
// and no child array is left behind: its subtree is collapsed bottom-up (every inner node
// given eight equal leaves, then pruned).
void strip(OcTree& t, OcTreeNode* n) {
  for (unsigned i = 0; i < 8; ++i)
    if (t.nodeChildExists(n, i) && t.nodeHasChildren(t.getNodeChild(n, i))) strip(t, t.getNodeChild(n, i));
  for (unsigned i = 0; i < 8; ++i) {
    if (!t.nodeChildExists(n, i)) t.createNodeChild(n, i);
    t.getNodeChild(n, i)->setLogOdds(0.0f);
  }
  t.pruneNode(n);
}

// Copies the children of `s` (and below) into the childless `d`; returns the nodes made.
uint64_t copy_below(const OcTree& src, const OcTreeNode* s, OcTree& dst, OcTreeNode* d) {
  uint64_t made = 0;
  for (unsigned i = 0; i < 8; ++i) {
    if (!src.nodeChildExists(s, i)) continue;
    const OcTreeNode* sc = src.getNodeChild(s, i);
    OcTreeNode* dc = dst.createNodeChild(d, i);
    dc->setLogOdds(sc->getLogOdds());
    made += 1 + copy_below(src, sc, dst, dc);
  }
  return made;
}

struct Walk {
  const OcTree& src;
  OcTree& dst;
  const RegionGrid& grid;
  std::unordered_set<RegionId>& dirty;
  uint64_t budget;
  RegionSyncSlice out;
  bool skipped = false;

  // `fresh`: `d` (or an ancestor) was made in this slice, so what is below it is not a copy yet.
  void node(const OcTreeNode* s, OcTreeNode* d, unsigned depth, const OcTreeKey& min_key, bool fresh) {
    if (depth == grid.depth) {
      region(s, d, min_key, fresh);
      return;
    }
    if (!src.nodeHasChildren(s)) {  // a leaf above the region depth
      if (dst.nodeHasChildren(d)) strip(dst, d);
      d->setLogOdds(s->getLogOdds());
      return;
    }
    d->setLogOdds(s->getLogOdds());
    for (unsigned i = 0; i < 8; ++i) {
      if (!src.nodeChildExists(s, i)) continue;
      const bool made = !dst.nodeChildExists(d, i);
      OcTreeNode* dc = made ? dst.createNodeChild(d, i) : dst.getNodeChild(d, i);
      node(src.getNodeChild(s, i), dc, depth + 1, detail::child_min_key(min_key, depth, i), fresh || made);
    }
    for (unsigned i = 0; i < 8; ++i) {  // after the children it keeps: `d` never loses its last one here
      if (src.nodeChildExists(s, i) || !dst.nodeChildExists(d, i)) continue;
      if (dst.nodeHasChildren(dst.getNodeChild(d, i))) strip(dst, dst.getNodeChild(d, i));
      dst.deleteNodeChild(d, i);
    }
  }

  void region(const OcTreeNode* s, OcTreeNode* d, const OcTreeKey& min_key, bool fresh) {
    const RegionId id = region_of(grid, min_key);
    const auto it = dirty.find(id);
    if (!fresh && it == dirty.end()) return;  // equal since its last copy
    if (out.nodes_copied >= budget && out.regions_copied > 0) {
      if (it == dirty.end()) dirty.insert(id);
      skipped = true;
      return;
    }
    if (dst.nodeHasChildren(d)) strip(dst, d);
    d->setLogOdds(s->getLogOdds());
    out.nodes_copied += 1 + copy_below(src, s, dst, d);
    out.regions_copied++;
    if (it != dirty.end()) dirty.erase(it);
  }
};

}  // namespace

std::unique_ptr<OcTree> empty_tree_like(const OcTree& src) {
  auto t = std::make_unique<OcTree>(src.getResolution());
  t->setOccupancyThres(src.getOccupancyThres());
  t->setProbHit(src.getProbHit());
  t->setProbMiss(src.getProbMiss());
  t->setClampingThresMin(src.getClampingThresMin());
  t->setClampingThresMax(src.getClampingThresMax());
  return t;
}

RegionSyncSlice sync_slice(const OcTree& src, OcTree& dst, const RegionGrid& grid, std::unordered_set<RegionId>& dirty,
                           uint64_t budget_nodes) {
  if (src.getResolution() != dst.getResolution()) throw std::invalid_argument("sync_slice: resolutions differ");
  Walk w{src, dst, grid, dirty, budget_nodes, {}};
  if (!src.getRoot()) {
    dst.clear();
  } else {
    // OctoMap makes a root only with a path below it: every node it made is fresh to the walk.
    const bool made = !dst.getRoot();
    if (made) dst.setNodeValue(OcTreeKey(0, 0, 0), 0.0f, true);
    w.node(src.getRoot(), dst.getRoot(), 0, OcTreeKey(0, 0, 0), made);
  }
  w.out.done = !w.skipped;
  if (w.out.done) dirty.clear();  // what is left was not met: inside a leaf of the source, or gone
  return w.out;
}

}  // namespace ort
