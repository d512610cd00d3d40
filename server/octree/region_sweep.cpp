#include "octree/region_sweep.h"

#include "octree/batched/node_access.h"

namespace ort {
namespace {

// The nodes above the region depth, post-order: inner values, then OctoMap's prune (never
// of a node whose children include a stand-in: region_sweep.h).
void settle_top(octomap::OcTree& tree, octomap::OcTreeNode* node, const octomap::OcTreeKey& min_key, unsigned depth,
                const RegionGrid& grid, const SweepSpill& spill) {
  if (depth >= grid.depth || !tree.nodeHasChildren(node)) return;
  bool stand_in = false;
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    const octomap::OcTreeKey k = detail::child_min_key(min_key, depth, i);
    settle_top(tree, tree.getNodeChild(node, i), k, depth + 1, grid, spill);
    if (depth + 1 == grid.depth && spill.spilled && spill.spilled(region_of(grid, k))) stand_in = true;
  }
  node->updateOccupancyChildren();
  if (depth > 0 && !stand_in) tree.pruneNode(node);  // OctoMap's prune() never prunes the root
}

unsigned child_index_at(const octomap::OcTreeKey& key, unsigned depth) {
  const unsigned bit = 15 - depth;
  return ((key[0] >> bit) & 1) | ((key[1] >> bit) & 1) << 1 | ((key[2] >> bit) & 1) << 2;
}

}  // namespace

octomap::OcTreeKey child_min_key(const octomap::OcTreeKey& min_key, unsigned depth, unsigned i) {
  return detail::child_min_key(min_key, depth, i);
}

void free_empty_child_array(octomap::OcTreeNode* node) {
  octomap::AbstractOcTreeNode**& children = detail::ChildArrayAccess::of(*node);
  if (children == nullptr) return;
  for (unsigned i = 0; i < 8; ++i)
    if (children[i] != nullptr) return;
  delete[] children;
  children = nullptr;
}

void delete_subtree(octomap::OcTree& tree, octomap::OcTreeNode* parent, unsigned i) {
  octomap::OcTreeNode* child = tree.getNodeChild(parent, i);
  octomap::AbstractOcTreeNode**& children = detail::ChildArrayAccess::of(*child);
  if (children != nullptr) {
    for (unsigned c = 0; c < 8; ++c)
      if (children[c] != nullptr) delete_subtree(tree, child, c);
    delete[] children;
    children = nullptr;
  }
  tree.deleteNodeChild(parent, i);  // the node itself, counted
}

RegionSweep::RegionSweep(const octomap::OcTree& tree, const RegionGrid& grid) : grid_(grid) {
  for_each_region(tree, grid, [&](RegionId id, const RegionNode& r) {
    octomap::OcTreeKey k = region_min_key(grid, id);
    const uint16_t mask = r.depth == 0 ? 0 : static_cast<uint16_t>(~((1u << (16 - r.depth)) - 1));
    for (unsigned a = 0; a < 3; ++a) k[a] = static_cast<uint16_t>(k[a] & mask);
    units_.push_back(Unit{k, r.depth});
  });
}

void RegionSweep::visit_unit(octomap::OcTree& tree, const Unit& unit, const RegionVisit& visit,
                             const StandInRule* rule) {
  const size_t nodes = tree.size();  // OctoMap's counter: every node made or deleted changes it
  sweep_unit(tree, unit, visit, rule);
  if (spill_.reshaped && tree.size() != nodes) spill_.reshaped(unit.min_key, unit.depth);
}

bool RegionSweep::visit_around(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth,
                               const octomap::OcTreeKey& min_key, const RegionVisit& visit, const StandInRule& rule) {
  const RegionGrid bound{spill_.depth};
  if (depth == spill_.depth) {
    const RegionId id = region_of(bound, min_key);
    if (tree.nodeHasChildren(node) || !spill_.stand_in(id)) return visit(tree, node, depth, min_key, visited_);
    ++visited_;
    switch (rule.now(tree, node, depth, min_key)) {
      case StandInFate::kUnchanged: return false;
      case StandInFate::kOwes:
        spill_.owe(id, rule.owed);
        ++owed_;
        return false;
      case StandInFate::kGone:
        spill_.drop(id);
        ++dropped_;
        return true;
    }
    return false;
  }
  ++visited_;
  bool stand_in_child = false;
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    octomap::OcTreeNode* child = tree.getNodeChild(node, i);
    const octomap::OcTreeKey k = detail::child_min_key(min_key, depth, i);
    if (visit_around(tree, child, depth + 1, k, visit, rule)) {
      delete_subtree(tree, node, i);
      ++deleted_;
    } else if (depth + 1 == spill_.depth && !tree.nodeHasChildren(child) && spill_.stand_in(region_of(bound, k))) {
      stand_in_child = true;
    }
  }
  if (!tree.nodeHasChildren(node)) {
    free_empty_child_array(node);
    return true;
  }
  node->updateOccupancyChildren();
  if (rule.prunes && depth > 0 && !stand_in_child) tree.pruneNode(node);  // as the visit prunes its own
  return false;
}

void RegionSweep::sweep_unit(octomap::OcTree& tree, const Unit& unit, const RegionVisit& visit,
                             const StandInRule* rule) {
  bool around = false;  // the unit holds stand-ins that stay on disk
  if (unit.depth == grid_.depth && spill_.spilled) {
    const RegionId id = region_of(grid_, unit.min_key);
    if (spill_.spilled(id)) {
      around = rule != nullptr && spill_.owe && spill_.drop && spill_.stand_in && spill_.depth >= grid_.depth &&
               (!spill_.can_owe || spill_.can_owe(id));
      if (!around && spill_.bring_back) spill_.bring_back(tree, id);
    }
  }
  octomap::OcTreeNode* root = tree.getRoot();
  if (root == nullptr) return;
  octomap::OcTreeNode* path[17];
  unsigned index[17];
  path[0] = root;
  unsigned depth = 0;
  for (; depth < unit.depth; ++depth) {
    octomap::OcTreeNode* node = path[depth];
    if (!tree.nodeHasChildren(node)) return;  // merged into a coarser leaf since the listing
    const unsigned i = child_index_at(unit.min_key, depth);
    if (!tree.nodeChildExists(node, i)) return;  // deleted since
    index[depth + 1] = i;
    path[depth + 1] = tree.getNodeChild(node, i);
  }
  ++regions_;
  const bool gone = around ? visit_around(tree, path[depth], depth, unit.min_key, visit, *rule)
                           : visit(tree, path[depth], depth, unit.min_key, visited_);
  if (!gone) {
    for (unsigned d = depth; d-- > 0;) path[d]->updateOccupancyChildren();
    return;
  }
  // The region's node goes, and every ancestor it leaves without children.
  while (depth > 0) {
    delete_subtree(tree, path[depth - 1], index[depth]);
    ++deleted_;
    --depth;
    if (tree.nodeHasChildren(path[depth])) {
      for (unsigned d = depth + 1; d-- > 0;) path[d]->updateOccupancyChildren();
      return;
    }
    free_empty_child_array(path[depth]);
  }
  tree.clear();  // nothing left: the root goes too (an empty tree, as OctoMap's after clear())
}

bool RegionSweep::run_slice(octomap::OcTree& tree, uint64_t node_budget, const RegionVisit& visit,
                            const StandInRule* stand_ins) {
  if (finished_) return true;
  const uint64_t start = visited_;
  do {
    if (next_ == units_.size()) break;
    visit_unit(tree, units_[next_++], visit, stand_ins);
  } while (visited_ - start < node_budget);
  if (next_ < units_.size()) return false;
  if (octomap::OcTreeNode* root = tree.getRoot()) settle_top(tree, root, octomap::OcTreeKey(0, 0, 0), 0, grid_, spill_);
  finished_ = true;
  return true;
}

}  // namespace ort
