// Box clears equal OctoMap's own per-voxel edits (setNodeValue / deleteNode for every key
// of the box, or for every key of it that OctoMap's search() finds, then updateInnerOccupancy
// and prune), node for node, and keep size() exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "brute_force.h"
#include "query/box_count.h"
#include "query/map_edit.h"
#include "query_test_maps.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

using query::ClearTo;
using query::KeyBox;

template <class F>
void for_each_key(const KeyBox& b, F&& f) {
  for (int x = b.min[0]; x <= b.max[0]; ++x)
    for (int y = b.min[1]; y <= b.max[1]; ++y)
      for (int z = b.min[2]; z <= b.max[2]; ++z) f(octomap::OcTreeKey(x, y, z));
}

// OctoMap's own way to set every known voxel of a box free: the reference of a clear that keeps
// unknown space unknown.
void octomap_clear_known_free(octomap::OcTree& t, const KeyBox& b) {
  for_each_key(b, [&](const octomap::OcTreeKey& k) {
    if (t.search(k)) t.setNodeValue(k, t.getClampingThresMinLog(), true);
  });
  t.updateInnerOccupancy();
  t.prune();
}

// octomap_server's clear_bbx (OctomapServer::clearBBXSrv): every leaf the bbx iterator finds
// set free whole, then updateInnerOccupancy. A leaf across the border changes outside the box.
void octomap_server_clear_bbx(octomap::OcTree& t, const KeyBox& b) {
  for (auto it = t.begin_leafs_bbx(b.min, b.max), end = t.end_leafs_bbx(); it != end; ++it)
    it->setLogOdds(t.getClampingThresMinLog());
  t.updateInnerOccupancy();
}

// OctoMap's own way to set every voxel of a box free. (Its deleteNode cannot be the
// reference for clearing to unknown: once a node's last child is deleted, deleting that
// node trips OctoMap's "children == NULL" assertion in 1.9.7. That case is checked
// voxel by voxel instead.)
void octomap_clear_free(octomap::OcTree& t, const KeyBox& b) {
  for_each_key(b, [&](const octomap::OcTreeKey& k) { t.setNodeValue(k, t.getClampingThresMinLog(), true); });
  t.updateInnerOccupancy();
  t.prune();
}

KeyBox grown(const KeyBox& b, int by) {
  KeyBox g;
  for (int i = 0; i < 3; ++i) {
    g.min[i] = static_cast<octomap::key_type>(std::max(0, b.min[i] - by));
    g.max[i] = static_cast<octomap::key_type>(std::min(65535, b.max[i] + by));
  }
  return g;
}

// Voxels around the box (2 voxels deep) that changed their log-odds or knownness, and voxels
// inside it that are not what the clear makes them: unknown (to unknown), free (to free, and
// with kKept unknown where they were unknown).
int64_t wrong_voxels(const octomap::OcTree& before, const octomap::OcTree& after, const KeyBox& b, ClearTo to,
                     query::Unknown unknown = query::Unknown::kMarked) {
  int64_t wrong = 0;
  for_each_key(grown(b, 2), [&](const octomap::OcTreeKey& k) {
    bool inside = true;
    for (int i = 0; i < 3; ++i) inside = inside && k[i] >= b.min[i] && k[i] <= b.max[i];
    const octomap::OcTreeNode* n = after.search(k);
    if (inside && to == ClearTo::kFree && unknown == query::Unknown::kKept && !before.search(k)) {
      wrong += n != nullptr;
    } else if (inside) {
      wrong += to == ClearTo::kUnknown ? n != nullptr : (!n || n->getLogOdds() != after.getClampingThresMinLog());
    } else {
      const octomap::OcTreeNode* o = before.search(k);
      wrong += (n == nullptr) != (o == nullptr) || (n && n->getLogOdds() != o->getLogOdds());
    }
  });
  return wrong;
}

// Around the box every voxel keeps its log-odds; inside, all are what the clear makes them.
void expect_box_cleared(const octomap::OcTree& before, const octomap::OcTree& after, const KeyBox& b, ClearTo to,
                        const std::string& where, query::Unknown unknown = query::Unknown::kMarked) {
  EXPECT_EQ(wrong_voxels(before, after, b, to, unknown), 0) << where;
  // Inner nodes hold OctoMap's values (the children's maximum) and size() is exact.
  octomap::OcTree recomputed(after);
  recomputed.updateInnerOccupancy();
  EXPECT_EQ(compare_structure(recomputed, after), "") << where;
  EXPECT_EQ(after.size(), after.calcNumNodes()) << where;
}

// The default clear to free: known voxels inside the box only, against OctoMap's setNodeValue
// of every key search() finds. octomap_server's clear_bbx (whole leaves) changes voxels
// outside the box on the same boxes of the same maps.
TEST(MapEdit, ClearKnownToFreeEqualsOctomapOnKnownVoxelsInsideTheBoxOnly) {
  std::mt19937 rng(40);
  int server_changes_outside = 0;  // over all maps: a pruned leaf across the border that is not yet at the minimum
  for (const NamedMap& m : query_test_maps()) {
    octomap::OcTree base(*m.tree);
    base.prune();
    int64_t unknown_kept = 0;
    for (int q = 0; q < 12; ++q) {
      const KeyBox b = random_box(base, rng, 24);
      octomap::OcTree ours(base), theirs(base);
      query::clear_box(ours, b, ClearTo::kFree, query::Unknown::kKept);
      octomap_clear_known_free(theirs, b);
      const std::string where = m.name + " q" + std::to_string(q);
      ASSERT_EQ(compare_structure(ours, theirs), "") << where;
      expect_box_cleared(base, ours, b, ClearTo::kFree, where, query::Unknown::kKept);
      unknown_kept += query::count_box(ours, b).unknown;
      octomap::OcTree server(base);
      octomap_server_clear_bbx(server, b);
      server_changes_outside += wrong_voxels(base, server, b, ClearTo::kFree, query::Unknown::kKept) > 0;
    }
    EXPECT_GT(unknown_kept, 0) << m.name;  // the boxes held unknown space, and it stayed unknown
  }
  EXPECT_GT(server_changes_outside, 0);
}

TEST(MapEdit, ClearToFreeIncludingUnknownEqualsOctomapSetNodeValue) {
  std::mt19937 rng(41);
  for (const NamedMap& m : query_test_maps()) {
    octomap::OcTree base(*m.tree);
    base.prune();  // the reference prunes the whole tree
    int mutant_disagrees = 0;
    for (int q = 0; q < 12; ++q) {
      const KeyBox b = random_box(base, rng, 24);
      octomap::OcTree ours(base), theirs(base);
      query::clear_box(ours, b, ClearTo::kFree, query::Unknown::kMarked);
      octomap_clear_free(theirs, b);
      const std::string where = m.name + " q" + std::to_string(q);
      ASSERT_EQ(compare_structure(ours, theirs), "") << where;
      expect_box_cleared(base, ours, b, ClearTo::kFree, where);
      // A wrong variant: clearing only the voxels that were known (octomap_server's
      // clear_bbx) differs wherever the box held unknown space.
      octomap::OcTree known_only(base);
      for_each_key(b, [&](const octomap::OcTreeKey& k) {
        if (known_only.search(k)) known_only.setNodeValue(k, known_only.getClampingThresMinLog());
      });
      mutant_disagrees += compare_structure(known_only, theirs) != "";
    }
    EXPECT_GT(mutant_disagrees, 0) << m.name;
  }
}

TEST(MapEdit, ClearToUnknownDeletesTheBoxOnly) {
  std::mt19937 rng(43);
  for (const NamedMap& m : query_test_maps()) {
    for (int q = 0; q < 12; ++q) {
      const KeyBox b = random_box(*m.tree, rng, 24);
      octomap::OcTree ours(*m.tree);
      query::clear_box(ours, b, ClearTo::kUnknown);
      expect_box_cleared(*m.tree, ours, b, ClearTo::kUnknown, m.name + " q" + std::to_string(q));
    }
  }
}

TEST(MapEdit, LargeBoxesKeepTheRestOfTheMapAndTheNodeCount) {
  std::mt19937 rng(42);
  for (const NamedMap& m : query_test_maps()) {
    for (int q = 0; q < 12; ++q) {
      // Thirds: to unknown, to free marking unknown space, to free on known space only.
      const ClearTo to = q % 3 == 0 ? ClearTo::kUnknown : ClearTo::kFree;
      const query::Unknown unknown = q % 3 == 1 ? query::Unknown::kMarked : query::Unknown::kKept;
      const KeyBox b = random_box(*m.tree, rng, 2000);
      octomap::OcTree t(*m.tree);
      query::clear_box(t, b, to, unknown);
      ASSERT_EQ(t.size(), t.calcNumNodes());
      const query::BoxCounts c = query::count_box(t, b), was = query::count_box(*m.tree, b);
      if (to == ClearTo::kUnknown) {
        EXPECT_EQ(c.unknown, b.voxels());
      } else if (unknown == query::Unknown::kMarked) {
        EXPECT_EQ(c.free, b.voxels());
      } else {
        EXPECT_EQ(c.unknown, was.unknown);
        EXPECT_EQ(c.free, was.free + was.occupied);
      }
      // Outside the box nothing changed: every leaf of either tree outside the box agrees.
      for (const octomap::OcTree* a : {static_cast<const octomap::OcTree*>(&t), m.tree})
        for (auto it = a->begin_leafs(), end = a->end_leafs(); it != end; ++it) {
          const octomap::OcTreeKey k = it.getKey();
          bool inside = true;
          for (int i = 0; i < 3; ++i) inside = inside && k[i] >= b.min[i] && k[i] <= b.max[i];
          if (inside) continue;
          const octomap::OcTreeNode* other = (a == &t ? m.tree : &t)->search(k);
          if (it.getDepth() < 16) continue;  // a big leaf may straddle the box; its finest voxels are checked by counts
          ASSERT_TRUE(other != nullptr);
          ASSERT_EQ(other->getLogOdds(), it->getLogOdds());
        }
    }
  }
}

TEST(MapEdit, ClearEverythingAndReset) {
  const octomap::OcTree& src = *query_test_maps()[1].tree;
  KeyBox all;
  all.min = octomap::OcTreeKey(0, 0, 0);
  all.max = octomap::OcTreeKey(65535, 65535, 65535);
  octomap::OcTree t(src);
  query::clear_box(t, all, ClearTo::kUnknown);
  EXPECT_EQ(t.size(), 0u);
  EXPECT_EQ(t.getRoot(), nullptr);
  query::clear_box(t, all, ClearTo::kFree);
  EXPECT_EQ(t.size(), 0u);  // nothing known: nothing to clear
  query::clear_box(t, all, ClearTo::kFree, query::Unknown::kMarked);
  EXPECT_EQ(t.size(), 1u);  // one pruned root, free
  EXPECT_EQ(query::count_box(t, all).free, int64_t(1) << 48);
  octomap::OcTree empty(0.1);
  KeyBox small;
  small.min = octomap::OcTreeKey(100, 200, 300);
  small.max = octomap::OcTreeKey(110, 203, 300);
  query::clear_box(empty, small, ClearTo::kFree, query::Unknown::kMarked);
  EXPECT_EQ(query::count_box(empty, small).free, small.voxels());
  EXPECT_EQ(query::count_box(empty, all).free, small.voxels());
  EXPECT_EQ(empty.size(), empty.calcNumNodes());
  query::reset_map(t);
  EXPECT_EQ(t.size(), 0u);
}

}  // namespace
}  // namespace ort::test
