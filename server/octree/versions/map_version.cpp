#include "octree/versions/map_version.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <sstream>

#include "core/memory_stream.h"

namespace ort {
namespace {

// OcTreeBaseImpl's tree_max_val at OctoMap's depth 16: the root's centre key.
constexpr octomap::key_type kRootKey = 32768;

// A tree whose sensor model is set as log-odds (OcTree's setters take probabilities and
// would round them).
class TreeWithParams : public octomap::OcTree {
 public:
  explicit TreeWithParams(const TreeParams& p) : octomap::OcTree(p.resolution) {
    prob_hit_log = p.prob_hit_log;
    prob_miss_log = p.prob_miss_log;
    occ_prob_thres_log = p.occupancy_thres_log;
    clamping_thres_min = p.clamp_min_log;
    clamping_thres_max = p.clamp_max_log;
  }
};

// One node's .ot record (OcTreeNode::writeData, then the child bits).
void append_record(std::string& out, const octomap::OcTree& tree, const octomap::OcTreeNode* node) {
  const float value = node->getValue();
  char rec[sizeof(float) + 1];
  std::memcpy(rec, &value, sizeof(float));
  unsigned bits = 0;
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) bits |= 1u << i;
  rec[sizeof(float)] = static_cast<char>(bits);
  out.append(rec, sizeof rec);
}

// The step for one leaf (its leaf iterator's key and depth) of the const getMetricMin/Max
// that snapshots of a copied tree report (calcMinMax rounds the max another way).
void extend(const octomap::OcTree& tree, const octomap::OcTreeKey& key, unsigned depth, double* mn, double* mx) {
  const double half = tree.getNodeSize(depth) / 2.0;
  for (unsigned a = 0; a < 3; ++a) {
    const double c = tree.keyToCoord(key[a], depth);
    if (c - half < mn[a]) mn[a] = c - half;
    if (c + half > mx[a]) mx[a] = c + half;
  }
}

void reset_extent(double* mn, double* mx) {
  for (unsigned a = 0; a < 3; ++a)
    mn[a] = std::numeric_limits<double>::max(), mx[a] = -std::numeric_limits<double>::max();
}

// Calls fn(child, child's key) for each existing child of `node` (at `depth`, key `key`), in
// OctoMap's child order: the order writeNodesRecurs writes them.
template <class Fn>
void for_each_child(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                    unsigned depth, Fn&& fn) {
  const octomap::key_type offset = kRootKey >> (depth + 1);
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) {
      octomap::OcTreeKey child;
      octomap::computeChildKey(i, offset, key, child);
      fn(tree.getNodeChild(node, i), child);
    }
}

// writeNodesRecurs below `node` into `r`, with the keys OctoMap's leaf iterator gives.
void write_subtree(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                   unsigned depth, RegionBytes& r) {
  append_record(r.bytes, tree, node);
  ++r.nodes;
  if (!tree.nodeHasChildren(node)) {
    extend(tree, key, depth, r.min, r.max);
    return;
  }
  for_each_child(tree, node, key, depth, [&](const octomap::OcTreeNode* c, const octomap::OcTreeKey& k) {
    write_subtree(tree, c, k, depth + 1, r);
  });
}

}  // namespace

TreeParams tree_params(const octomap::OcTree& tree) {
  TreeParams p;
  p.resolution = tree.getResolution();
  p.prob_hit_log = tree.getProbHitLog();
  p.prob_miss_log = tree.getProbMissLog();
  p.occupancy_thres_log = tree.getOccupancyThresLog();
  p.clamp_min_log = tree.getClampingThresMinLog();
  p.clamp_max_log = tree.getClampingThresMaxLog();
  return p;
}

std::unique_ptr<octomap::OcTree> make_tree(const TreeParams& p) { return std::make_unique<TreeWithParams>(p); }

std::string MapVersion::header() const {
  // AbstractOcTree::write's header of an empty tree at this resolution, with this size.
  std::ostringstream out(std::ios::binary);
  octomap::OcTree(params_.resolution).write(out);
  std::string h = std::move(out).str();
  const std::string empty_size = "\nsize 0\n";
  const size_t at = h.find(empty_size);
  if (at != std::string::npos) h.replace(at, empty_size.size(), "\nsize " + std::to_string(nodes_) + "\n");
  return h;
}

size_t MapVersion::data_bytes() const {
  size_t n = top_.size();
  for (const auto& [offset, r] : regions_) n += r->bytes.size();
  return n;
}

void MapVersion::append_data(std::string& out) const {
  size_t at = 0;
  for (const auto& [offset, r] : regions_) {
    out.append(top_, at, offset - at);
    out.append(r->bytes);
    at = offset;
  }
  out.append(top_, at, std::string::npos);
}

std::string MapVersion::ot_bytes() const {
  std::string out = header();
  out.reserve(out.size() + data_bytes());
  append_data(out);
  return out;
}

bool MapVersion::write_ot(std::ostream& out) const {
  const std::string h = header();
  out.write(h.data(), static_cast<std::streamsize>(h.size()));
  size_t at = 0;
  for (const auto& [offset, r] : regions_) {
    out.write(top_.data() + at, static_cast<std::streamsize>(offset - at));
    out.write(r->bytes.data(), static_cast<std::streamsize>(r->bytes.size()));
    at = offset;
  }
  out.write(top_.data() + at, static_cast<std::streamsize>(top_.size() - at));
  return static_cast<bool>(out);
}

std::unique_ptr<octomap::OcTree> MapVersion::tree() const {
  std::unique_ptr<octomap::OcTree> t = make_tree(params_);
  if (nodes_ == 0) return t;
  std::string data;
  data.reserve(data_bytes());
  append_data(data);
  MemoryStream in(data);
  t->readData(in);
  return t;
}

void MapVersionBuilder::changed(std::span<const VoxelUpdate> voxels) {
  if (all_) return;
  RegionId last = ~RegionId{0};
  for (const VoxelUpdate& v : voxels) {
    const RegionId id = region_of(grid_, v.key());
    if (id != last) dirty_.insert(id), last = id;
  }
}

void MapVersionBuilder::walk(const octomap::OcTree& tree, const octomap::OcTreeNode* node,
                             const octomap::OcTreeKey& key, unsigned depth, MapVersion& v) {
  if (depth == grid_.depth) {
    const RegionId id = region_of(grid_, key);
    std::shared_ptr<const RegionBytes> r;
    if (!all_ && !dirty_.contains(id))
      if (auto it = kept_.find(id); it != kept_.end()) r = it->second;
    if (!r) {
      auto fresh = std::make_shared<RegionBytes>();
      reset_extent(fresh->min, fresh->max);
      write_subtree(tree, node, key, depth, *fresh);
      last_.regions_written++;
      last_.bytes_written += fresh->bytes.size();
      r = std::move(fresh);
    }
    v.nodes_ += r->nodes;
    for (unsigned a = 0; a < 3; ++a)
      v.min_[a] = std::min(v.min_[a], r->min[a]), v.max_[a] = std::max(v.max_[a], r->max[a]);
    v.regions_.emplace_back(v.top_.size(), r);
    next_.emplace(id, std::move(r));
    return;
  }
  append_record(v.top_, tree, node);
  ++v.nodes_;
  if (!tree.nodeHasChildren(node)) {  // a coarse leaf above the region depth
    extend(tree, key, depth, v.min_, v.max_);
    return;
  }
  for_each_child(tree, node, key, depth,
                 [&](const octomap::OcTreeNode* c, const octomap::OcTreeKey& k) { walk(tree, c, k, depth + 1, v); });
}

std::shared_ptr<const MapVersion> MapVersionBuilder::build(const octomap::OcTree& tree) {
  auto v = std::make_shared<MapVersion>();
  v->params_ = tree_params(tree);
  last_ = Figures{};
  next_.clear();
  next_.reserve(kept_.size() + 16);
  if (const octomap::OcTreeNode* root = tree.getRoot()) {
    reset_extent(v->min_, v->max_);
    walk(tree, root, octomap::OcTreeKey(kRootKey, kRootKey, kRootKey), 0, *v);
  }
  // Regions no longer in the tree are forgotten: one made again later is written anew.
  kept_.swap(next_);
  next_.clear();
  dirty_.clear();
  all_ = false;
  last_.regions = v->regions_.size();
  return v;
}

}  // namespace ort
