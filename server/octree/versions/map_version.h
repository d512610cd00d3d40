// An immutable version of a map, kept per region: what whole-map readers (snapshots, saves,
// the viewer publisher) read without holding the tree's lock or copying its nodes.
//
// Each region (octree/region.h: the subtree at one fixed depth) is kept as the bytes OctoMap's
// .ot writes for it (OcTreeBaseImpl::writeNodesRecurs: a node's log-odds, a byte of child
// bits, then its children depth first in child order), shared by every version in which the
// region did not change; the nodes above the region depth are kept as the same records, with
// the place where each region's bytes go. So a version's .ot is its top and its regions'
// bytes written in order: OctoMap's AbstractOcTree::write byte for byte.
//
// Building the next version (MapVersionBuilder::build) walks the nodes above the region depth
// (O(regions)) and writes again only the regions a change reached since the last build, and of
// those only the cells (a region's nodes 3 levels below its root) where it changed: the rest of
// the region is copied from its old records (octree/versions/region_records.h). The builder is
// told the keys of the scans applied since, or better the leaves their updates changed (the
// octree stage's change log; MapVersionBuilder::changed), or to write every region after a
// change that does not list its keys (changed_all: an edit, a reset). So a version costs in
// proportion to what changed, not to the nodes of the regions it reached.
// Why a subtree no changed key lies in is unchanged: OctoMap's update (and the batched stage,
// which does what it does) creates, expands, prunes and changes nodes only on the paths of the
// keys it updates; a subtree pruned into a coarser leaf above it was a leaf itself first, and
// one made again by expanding that coarse leaf has the coarse leaf's value, which is its own
// (the coarse leaf cannot change without being expanded); the nodes above the region depth are
// written anew at every build.
// Why the change log is enough: an update of a key whose leaf (or the pruned node above it)
// is at the clamping bound returns before it touches the tree (updateNode's early return);
// every other update changes the leaf's value and is logged (octree/leaf_changes.h; a key
// updated several times in one list is logged once, even where its value comes back to what
// it was). tests/octree/map_version_test.cpp checks the bytes against OcTree::write after
// every scan of real data, told either way.
//
// Memory: a region's bytes are 5 per node (a tree's node costs 16 to 80); the newest version
// holds one such copy of the whole map, and an older version a reader still holds adds at most
// the regions that changed since it (docs/ARCHITECTURE.md "Readers and the read replica").
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/leaf_changes.h"
#include "octree/region.h"
#include "octree/versions/region_records.h"
#include "octree/worker_pool.h"

namespace ort {

// The tree's resolution and sensor model as log-odds (a tree made from a version gets them
// bit for bit: the .bt's maximum likelihood depends on them).
struct TreeParams {
  double resolution = 0.1;
  float prob_hit_log = 0, prob_miss_log = 0, occupancy_thres_log = 0, clamp_min_log = 0, clamp_max_log = 0;
};
TreeParams tree_params(const octomap::OcTree& tree);
// An empty tree with `p`'s resolution and sensor model.
std::unique_ptr<octomap::OcTree> make_tree(const TreeParams& p);

class MapVersion {
 public:
  // AbstractOcTree::write's bytes (header and data) of the tree the version is of.
  std::string ot_bytes() const;
  bool write_ot(std::ostream& out) const;
  // The tree itself, made from the bytes (its own nodes: a reader may change it).
  std::unique_ptr<octomap::OcTree> tree() const;
  uint64_t nodes() const { return nodes_; }  // OcTree::size()
  // OcTree::getMetricMin/Max of the tree (the const ones: on a copy of it, as snapshots had).
  void metric_min(double& x, double& y, double& z) const { x = min_[0], y = min_[1], z = min_[2]; }
  void metric_max(double& x, double& y, double& z) const { x = max_[0], y = max_[1], z = max_[2]; }
  size_t regions() const { return regions_.size(); }
  size_t data_bytes() const;  // what writeData writes

 private:
  friend class MapVersionBuilder;
  std::string header() const;
  void append_data(std::string& out) const;
  TreeParams params_;
  std::string top_;  // the records of the nodes above the region depth, in write order
  // Each region's bytes and the offset in top_ they go at (offsets ascending).
  std::vector<std::pair<size_t, std::shared_ptr<const RegionBytes>>> regions_;
  uint64_t nodes_ = 0;
  double min_[3] = {0, 0, 0}, max_[3] = {0, 0, 0};
};

class MapVersionBuilder {
 public:
  // `cells` false: a changed region is written whole from the tree (the design before the
  // changed cells; benchmarks compare).
  explicit MapVersionBuilder(RegionGrid grid, bool cells = true) : grid_(grid), cells_(cells) {}
  // The tree changed at these keys (a scan's voxel list) since the last build.
  void changed(std::span<const VoxelUpdate> voxels);
  // The same from the octree stage's log of the leaves an update changed: fewer regions where
  // scans cross space they already made certain (its keys at the clamping bound).
  void changed(const LeafChanges& log);
  // The tree changed in a way that does not list its keys: the next build writes every region.
  void changed_all() { all_ = true; }
  // The version of `tree` as it is now. The caller keeps the tree from changing meanwhile.
  // With `pool`, its threads write the regions that changed (each region's bytes its own).
  std::shared_ptr<const MapVersion> build(const octomap::OcTree& tree, WorkerPool* pool = nullptr);

  struct Figures {
    uint64_t regions = 0, regions_written = 0, bytes_written = 0;
    uint64_t regions_merged = 0;                   // of those written: from their old records and the changed cells
    uint64_t nodes_written = 0, nodes_copied = 0;  // of the regions written: all, copied from old records
  };
  Figures last_build() const { return last_; }

 private:
  void walk(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key, unsigned depth,
            MapVersion& v);
  void mark(const octomap::OcTreeKey& key);
  // A region the build writes after its walk: into the version's slot, from its old records
  // and changed cells (old set) or whole.
  struct Job {
    size_t slot;
    const octomap::OcTreeNode* node;
    octomap::OcTreeKey key;
    unsigned depth;
    const RegionBytes* old;
    const RegionCells* cells;
    uint64_t copied = 0;  // nodes copied from `old`
  };
  std::vector<Job> jobs_;
  std::vector<RegionId> ids_;  // the version's regions, in order
  RegionGrid grid_;
  bool cells_;
  bool all_ = true;                                  // the first build writes everything
  std::unordered_map<RegionId, RegionCells> dirty_;  // the cells changed since the last build
  RegionId last_id_ = ~RegionId{0};
  RegionCells* last_cells_ = nullptr;
  std::unordered_map<RegionId, std::shared_ptr<const RegionBytes>> kept_, next_;
  Figures last_;
};

}  // namespace ort
