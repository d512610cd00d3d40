#include "daemon/serving/octomap_raw_map.h"

#include <cstdio>
#include <sstream>

#include "core/file_checks/octree_binary.h"
#include "octree/region_sweep.h"

namespace ort::daemon {
namespace {

// What OcTree::writeBinary writes (max likelihood, pruned: OctoMap's readers and test_io
// expect it), without changing the map.
std::string binary_bytes(const octomap::OcTree& tree) { return octomap_binary_bytes(tree); }

octomap::raw_t message_of(const std::string& bytes, int64_t utime) {
  octomap::raw_t m;
  m.utime = utime;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.transform[r][c] = r == c ? 1.0 : 0.0;
  m.length = static_cast<int32_t>(bytes.size());
  m.data.assign(bytes.begin(), bytes.end());
  return m;
}

std::string metres(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", m);
  return buf;
}

std::string kib(size_t bytes) { return std::to_string((bytes + 1023) / 1024) + " KiB"; }

}  // namespace

size_t raw_message_bytes(size_t data_bytes) { return 8 /* fingerprint */ + 8 + 16 * 8 + 4 + data_bytes; }

octomap::OcTree cut_at_depth(const octomap::OcTree& tree, unsigned depth) {
  const unsigned levels = tree.getTreeDepth() - depth;  // levels cut off below `depth`
  octomap::OcTree out(tree.getResolution() * double(1u << levels));
  out.setOccupancyThres(tree.getOccupancyThres());
  out.setClampingThresMin(tree.getClampingThresMin());
  out.setClampingThresMax(tree.getClampingThresMax());
  const int centre = 1 << (tree.getTreeDepth() - 1);  // key of the origin (32768) in both trees
  for (auto it = tree.begin_leafs(depth), end = tree.end_leafs(); it != end; ++it) {
    // The node's smallest key, in coarse voxels; a leaf above `depth` spans n^3 of them.
    const octomap::OcTreeKey k = it.getIndexKey();
    const unsigned n = 1u << (depth - it.getDepth());
    octomap::OcTreeKey c;
    for (unsigned dx = 0; dx < n; ++dx)
      for (unsigned dy = 0; dy < n; ++dy)
        for (unsigned dz = 0; dz < n; ++dz) {
          const unsigned d[3] = {dx, dy, dz};
          for (int i = 0; i < 3; ++i)
            c[i] = static_cast<octomap::key_type>(centre + ((int(k[i]) - centre) >> levels) + int(d[i]));
          out.setNodeValue(c, it->getLogOdds(), true);
        }
  }
  out.updateInnerOccupancy();
  out.prune();
  return out;
}

RawMap make_raw_map(const octomap::OcTree& tree, int64_t utime, const RawMapOptions& options) {
  RawMap r;
  std::string bytes = binary_bytes(tree);
  r.full_bytes = raw_message_bytes(bytes.size());
  const unsigned full_depth = tree.getTreeDepth();
  for (unsigned depth = full_depth; depth >= options.min_depth && depth > 0; --depth) {
    if (depth < full_depth) bytes = binary_bytes(cut_at_depth(tree, depth));
    if (raw_message_bytes(bytes.size()) > options.max_bytes) continue;
    r.message = message_of(bytes, utime);
    r.depth = depth;
    if (depth < full_depth)
      r.note = "OCTOMAP map depth-limited to " + std::to_string(depth) + " of " + std::to_string(full_depth) + " (" +
               metres(tree.getResolution() * double(1u << (full_depth - depth))) + " m voxels): " + kib(r.full_bytes) +
               " at full depth > cap " + kib(options.max_bytes);
    return r;
  }
  r.depth = 0;
  r.note = "OCTOMAP map not published: " + kib(raw_message_bytes(bytes.size())) + " even at depth " +
           std::to_string(options.min_depth) + " > cap " + kib(options.max_bytes);
  return r;
}

namespace {

// Deletes the occupied leaves below `node` (at `depth`, min-corner key `min_key`) whose centre
// z is outside (lo, hi), keeping inner values the max of their children; true when `node`
// is left without children (its parent then deletes it, as OctoMap's deleteNode would).
bool drop_below(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth, const octomap::OcTreeKey& min_key,
                double lo, double hi, size_t& dropped) {
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    octomap::OcTreeNode* child = tree.getNodeChild(node, i);
    const octomap::OcTreeKey key = child_min_key(min_key, depth, i);
    if (!tree.nodeHasChildren(child)) {
      const double z = tree.keyToCoord(key[2], depth + 1);
      if (tree.isNodeOccupied(child) && !(z > lo && z < hi)) delete_subtree(tree, node, i), ++dropped;
    } else if (drop_below(tree, child, depth + 1, key, lo, hi, dropped)) {
      delete_subtree(tree, node, i);
    }
  }
  if (!tree.nodeHasChildren(node)) {
    free_empty_child_array(node);
    return true;
  }
  node->updateOccupancyChildren();
  return false;
}

}  // namespace

size_t drop_occupied_outside_band(octomap::OcTree& tree, double min_z, double max_z) {
  size_t dropped = 0;
  octomap::OcTreeNode* root = tree.getRoot();
  if (!root) return 0;
  if (!tree.nodeHasChildren(root)) {  // a map of one leaf: the root itself
    if (tree.isNodeOccupied(root) && !(0.0 > min_z && 0.0 < max_z)) tree.clear(), dropped = 1;
    return dropped;
  }
  if (drop_below(tree, root, 0, octomap::OcTreeKey(0, 0, 0), min_z, max_z, dropped)) tree.clear();
  return dropped;
}

}  // namespace ort::daemon
