#include "octree/decay.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ort {
namespace {

// Post-order decay of `node`'s subtree; true when the caller must delete `node` (a leaf
// below the threshold, or an inner node left without children).
bool decay_node(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth, const DecayRule& rule,
                uint64_t& visited, uint64_t& decayed, uint64_t& deleted) {
  ++visited;
  if (!tree.nodeHasChildren(node)) {
    ++decayed;
    const float l = node->getLogOdds() * rule.factor;
    node->setLogOdds(l);
    return std::fabs(l) < rule.delete_below;
  }
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    if (decay_node(tree, tree.getNodeChild(node, i), depth + 1, rule, visited, decayed, deleted)) {
      delete_subtree(tree, node, i);
      ++deleted;
    }
  }
  if (!tree.nodeHasChildren(node)) {
    free_empty_child_array(node);
    return true;
  }
  node->updateOccupancyChildren();
  if (depth > 0) tree.pruneNode(node);  // OctoMap's prune() never prunes the root
  return false;
}

}  // namespace

float decay_factor(double step_s, double half_life_s) {
  if (!std::isfinite(half_life_s) || half_life_s <= 0)
    throw std::invalid_argument("decay half-life " + std::to_string(half_life_s) + " s is not a positive number");
  if (!std::isfinite(step_s) || step_s < 0)
    throw std::invalid_argument("decay step " + std::to_string(step_s) + " s is not a non-negative number");
  return static_cast<float>(std::exp2(-step_s / half_life_s));
}

bool decay_subtree(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth, const DecayRule& rule) {
  uint64_t visited = 0, decayed = 0, deleted = 0;
  return decay_node(tree, node, depth, rule, visited, decayed, deleted);
}

DecaySweep::DecaySweep(const octomap::OcTree& tree, const RegionGrid& grid, const DecayRule& rule)
    : sweep_(tree, grid), rule_(rule) {
  stand_ins_.now = [rule](octomap::OcTree&, octomap::OcTreeNode* stand_in, unsigned, const octomap::OcTreeKey&) {
    stand_in->setLogOdds(stand_in->getLogOdds() * rule.factor);
    return StandInFate::kOwes;
  };
  stand_ins_.owed = std::make_shared<const RegionStep>(
      [rule](octomap::OcTree& t, octomap::OcTreeNode* node, unsigned depth, const octomap::OcTreeKey&) {
        return decay_subtree(t, node, depth, rule);
      });
  stand_ins_.prunes = true;
}

bool DecaySweep::run_slice(octomap::OcTree& tree, uint64_t node_budget) {
  return sweep_.run_slice(
      tree, node_budget,
      [this](octomap::OcTree& t, octomap::OcTreeNode* node, unsigned depth, const octomap::OcTreeKey&,
             uint64_t& visited) {
        return decay_node(t, node, depth, rule_, visited, leaves_decayed_, leaves_deleted_);
      },
      &stand_ins_);
}

DecayStats DecaySweep::stats() const {
  DecayStats st;
  st.nodes_visited = sweep_.nodes_visited();
  st.leaves_decayed = leaves_decayed_;
  st.nodes_deleted = leaves_deleted_ + sweep_.nodes_deleted();
  st.regions = sweep_.regions_visited();
  return st;
}

DecayStats decay_tree(octomap::OcTree& tree, const RegionGrid& grid, const DecayRule& rule) {
  DecaySweep sweep(tree, grid, rule);
  sweep.run_slice(tree, UINT64_MAX);
  return sweep.stats();
}

}  // namespace ort
