#include "octree/versions/map_version.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>
#include <sstream>

#include "core/memory_stream.h"
#include "octree/versions/region_records.h"

namespace ort {
namespace {

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

void MapVersionBuilder::mark(const octomap::OcTreeKey& key) {
  const RegionId id = region_of(grid_, key);
  if (id != last_id_) last_cells_ = &dirty_[id], last_id_ = id;
  last_cells_->set(cell_of(key, grid_.depth));
}

void MapVersionBuilder::changed(std::span<const VoxelUpdate> voxels) {
  if (all_) return;
  last_id_ = ~RegionId{0};
  for (const VoxelUpdate& v : voxels) mark(v.key());
}

void MapVersionBuilder::changed(const LeafChanges& log) {
  if (all_) return;
  last_id_ = ~RegionId{0};
  log.for_each([&](const LeafChange& c) { mark(c.key()); });
}

void MapVersionBuilder::walk(const octomap::OcTree& tree, const octomap::OcTreeNode* node,
                             const octomap::OcTreeKey& key, unsigned depth, MapVersion& v) {
  if (depth == grid_.depth) {
    const RegionId id = region_of(grid_, key);
    const auto kept = all_ ? kept_.end() : kept_.find(id);
    const auto cells = kept == kept_.end() ? dirty_.end() : dirty_.find(id);
    ids_.push_back(id);
    if (kept != kept_.end() && cells == dirty_.end()) {  // unchanged: the old one
      v.regions_.emplace_back(v.top_.size(), kept->second);
    } else {  // written after the walk: merged from its old records, or whole
      const bool merge = kept != kept_.end() && cells_;
      jobs_.push_back(Job{v.regions_.size(), node, key, depth, merge ? kept->second.get() : nullptr,
                          merge ? &cells->second : nullptr});
      v.regions_.emplace_back(v.top_.size(), nullptr);
    }
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

std::shared_ptr<const MapVersion> MapVersionBuilder::build(const octomap::OcTree& tree, WorkerPool* pool) {
  auto v = std::make_shared<MapVersion>();
  v->params_ = tree_params(tree);
  last_ = Figures{};
  jobs_.clear();
  ids_.clear();
  if (const octomap::OcTreeNode* root = tree.getRoot()) {
    reset_extent(v->min_, v->max_);
    walk(tree, root, octomap::OcTreeKey(kRootKey, kRootKey, kRootKey), 0, *v);
  }
  // The regions to write, on the pool's threads where there is one (each its own bytes).
  std::atomic<size_t> next_job{0};
  auto write = [&](unsigned) {
    for (size_t i; (i = next_job.fetch_add(1, std::memory_order_relaxed)) < jobs_.size();) {
      Job& j = jobs_[i];
      auto fresh = std::make_shared<RegionBytes>();
      if (j.old)
        j.copied = merge_region(tree, j.node, j.key, j.depth, *j.old, *j.cells, *fresh);
      else
        write_region(tree, j.node, j.key, j.depth, *fresh);
      v->regions_[j.slot].second = std::move(fresh);
    }
  };
  if (pool && jobs_.size() > 1)
    pool->run_shared(write);
  else
    write(0);
  for (const Job& j : jobs_) {
    last_.regions_merged += j.old != nullptr;
    last_.bytes_written += v->regions_[j.slot].second->bytes.size();
    last_.nodes_written += v->regions_[j.slot].second->nodes;
    last_.nodes_copied += j.copied;
  }
  last_.regions_written = jobs_.size();
  next_.clear();
  next_.reserve(v->regions_.size());
  for (size_t k = 0; k < v->regions_.size(); ++k) {
    const RegionBytes& r = *v->regions_[k].second;
    v->nodes_ += r.nodes;
    for (unsigned a = 0; a < 3; ++a)
      v->min_[a] = std::min(v->min_[a], r.min[a]), v->max_[a] = std::max(v->max_[a], r.max[a]);
    next_.emplace(ids_[k], v->regions_[k].second);
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
