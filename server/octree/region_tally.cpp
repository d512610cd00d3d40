#include "octree/region_tally.h"

#include <utility>

namespace ort {
namespace {

uint64_t inner_below(const octomap::OcTree& tree, const octomap::OcTreeNode* node) {
  if (!tree.nodeHasChildren(node)) return 0;
  uint64_t n = 1;
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) n += inner_below(tree, tree.getNodeChild(node, i));
  return n;
}

}  // namespace

void RegionTally::changed(RegionId id) {
  if (!all_changed_) changed_.insert(id);
}

void RegionTally::changed_box(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi) {
  if (all_changed_) return;
  const unsigned s = grid_.shift();
  uint64_t cells = 1;
  for (unsigned a = 0; a < 3; ++a) {
    if (hi[a] < lo[a]) return;  // an empty box
    cells *= uint64_t((hi[a] >> s) - (lo[a] >> s) + 1);
  }
  if (cells > kMaxBoxRegions) return changed_all();
  for (unsigned z = lo[2] >> s; z <= unsigned(hi[2] >> s); ++z)
    for (unsigned y = lo[1] >> s; y <= unsigned(hi[1] >> s); ++y)
      for (unsigned x = lo[0] >> s; x <= unsigned(hi[0] >> s); ++x)
        changed_.insert(region_of(grid_, octomap::OcTreeKey(uint16_t(x << s), uint16_t(y << s), uint16_t(z << s))));
}

void RegionTally::changed_all() {
  all_changed_ = true;
  changed_.clear();
}

uint64_t RegionTally::count_below(const octomap::OcTree& tree, const octomap::OcTreeNode* node,
                                  const octomap::OcTreeKey& min_key, unsigned depth,
                                  std::unordered_map<RegionId, uint64_t>& next) {
  if (!tree.nodeHasChildren(node)) return 0;  // a leaf (a stand-in, a pruned node) at any depth
  if (depth == grid_.depth) {
    const RegionId id = region_of(grid_, min_key);
    uint64_t n;
    auto it = inner_.find(id);
    if (!all_changed_ && it != inner_.end() && changed_.count(id) == 0) {
      n = it->second;
      ++reused_;
    } else {
      n = inner_below(tree, node);
      ++recounted_;
    }
    next.emplace(id, n);
    return n;
  }
  uint64_t n = 1;
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i))
      n += count_below(tree, tree.getNodeChild(node, i), detail::child_min_key(min_key, depth, i), depth + 1, next);
  return n;
}

uint64_t RegionTally::inner_nodes(const octomap::OcTree& tree) {
  std::unordered_map<RegionId, uint64_t> next;
  next.reserve(inner_.size() + 16);
  const octomap::OcTreeNode* root = const_cast<octomap::OcTree&>(tree).getRoot();
  const uint64_t n = root == nullptr ? 0 : count_below(tree, root, octomap::OcTreeKey(0, 0, 0), 0, next);
  inner_ = std::move(next);
  changed_.clear();
  all_changed_ = false;
  return n;
}

uint64_t RegionTally::memory(const octomap::OcTree& tree) {
  using Base = octomap::OcTreeBaseImpl<octomap::OcTreeNode, octomap::AbstractOccupancyOcTree>;
  return sizeof(Base) + tree.memoryUsageNode() * tree.size() + inner_nodes(tree) * sizeof(octomap::OcTreeNode* [8]);
}

}  // namespace ort
