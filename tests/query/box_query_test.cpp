// Box counts and region extraction give exactly the voxel-by-voxel answers of OctoMap's
// search() for boxes of every size, and the rules' wrong variants are caught.
#include <gtest/gtest.h>

#include <random>

#include "brute_force.h"
#include "query/box_count.h"
#include "query/leaf_walk.h"
#include "query/region_extract.h"
#include "query_test_maps.h"

namespace ort::test {
namespace {

using query::BoxCounts;
using query::KeyBox;

void expect_counts(const BoxCounts& got, const BoxCounts& want, const std::string& where) {
  EXPECT_EQ(got.occupied, want.occupied) << where;
  EXPECT_EQ(got.free, want.free) << where;
  EXPECT_EQ(got.unknown, want.unknown) << where;
}

std::string describe(const std::string& map, const KeyBox& b) {
  return map + " box [" + std::to_string(b.min[0]) + "," + std::to_string(b.min[1]) + "," + std::to_string(b.min[2]) +
         "]..[" + std::to_string(b.max[0]) + "," + std::to_string(b.max[1]) + "," + std::to_string(b.max[2]) + "]";
}

// A wrong variant: counting each visited leaf's whole cube (no intersection with the box)
// and trusting OctoMap's iterator to visit only leaves inside the box.
BoxCounts whole_leaf_counts(const octomap::OcTree& t, const KeyBox& box) {
  BoxCounts c;
  for (auto it = t.begin_leafs_bbx(box.min, box.max), end = t.end_leafs_bbx(); it != end; ++it) {
    const int64_t side = int64_t(1) << (t.getTreeDepth() - it.getDepth());
    (t.isNodeOccupied(*it) ? c.occupied : c.free) += side * side * side;
  }
  c.unknown = box.voxels() - c.occupied - c.free;
  return c;
}

TEST(BoxQuery, CountsEqualOneSearchPerVoxel) {
  std::mt19937 rng(21);
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    int with_occupied = 0, mutant_disagrees = 0;
    for (int q = 0; q < 1500; ++q) {
      const KeyBox b = random_box(t, rng, 60);
      const BoxCounts got = query::count_box(t, b);
      const BoxCounts want = brute_counts(t, b);
      expect_counts(got, want, describe(m.name, b));
      ASSERT_EQ(query::any_occupied(t, b), want.occupied > 0) << describe(m.name, b);
      with_occupied += want.occupied > 0;
      const BoxCounts bad = whole_leaf_counts(t, b);
      mutant_disagrees += bad.occupied != want.occupied || bad.free != want.free;
      if (HasFailure()) return;
    }
    EXPECT_GT(with_occupied, 100) << m.name;
    EXPECT_GT(mutant_disagrees, 100) << m.name << ": the intersection rule is not exercised";
  }
}

TEST(BoxQuery, LargeBoxesEqualCountsOverAllLeaves) {
  // Up to the whole key range (2.8e14 voxels): the reference walks every stored leaf.
  std::mt19937 rng(22);
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    for (int q = 0; q < 60; ++q) {
      const KeyBox b = random_box(t, rng, q < 50 ? 4000 : 65536);
      expect_counts(query::count_box(t, b), all_leaves_counts(t, b), describe(m.name, b));
    }
    KeyBox all;
    all.min = octomap::OcTreeKey(0, 0, 0);
    all.max = octomap::OcTreeKey(65535, 65535, 65535);
    const BoxCounts whole = query::count_box(t, all);
    expect_counts(whole, all_leaves_counts(t, all), m.name + " whole key range");
    EXPECT_EQ(whole.occupied + whole.free + whole.unknown, int64_t(1) << 48);
  }
}

TEST(BoxQuery, MetricBoxUsesOctomapKeysAndClampsToTheKeyRange) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  const KeyBox b = query::key_box(t, octomap::point3d(-1.05f, 0.f, 0.3f), octomap::point3d(2.f, 0.4f, 0.3f));
  for (int i = 0; i < 3; ++i) {
    const float lo[3] = {-1.05f, 0.f, 0.3f}, hi[3] = {2.f, 0.4f, 0.3f};
    EXPECT_EQ(b.min[i], t.coordToKey(double(lo[i])));
    EXPECT_EQ(b.max[i], t.coordToKey(double(hi[i])));
  }
  const double far_lo[3] = {-1e9, -1, -1}, far_hi[3] = {1e9, 1, 1};
  const KeyBox c = query::key_box(t, far_lo, far_hi);
  EXPECT_EQ(c.min[0], 0);
  EXPECT_EQ(c.max[0], 65535);
  // Found by fuzz_query_message: OctoMap's coordToKeyChecked converts floor(c / res) to int
  // before its range check, undefined for a corner like -5.3e304; such corners clamp too.
  const double huge_lo[3] = {-5.3e304, -1, -1}, huge_hi[3] = {1e300, 1, 1};
  const KeyBox h = query::key_box(t, huge_lo, huge_hi);
  EXPECT_EQ(h.min[0], 0);
  EXPECT_EQ(h.max[0], 65535);
  const double nan_lo[3] = {NAN, 0, 0}, inverted_hi[3] = {1e9, -2, 1};
  EXPECT_THROW(query::key_box(t, nan_lo, far_hi), query::QueryError);
  EXPECT_THROW(query::key_box(t, far_lo, inverted_hi), query::QueryError);
}

TEST(RegionQuery, NodesAtDepthEqualSearchAtDepth) {
  std::mt19937 rng(23);
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    int nonempty = 0, mutant_disagrees = 0;
    for (int q = 0; q < 400; ++q) {
      const unsigned depth = q % 3 == 0 ? 16 : std::uniform_int_distribution<unsigned>(10, 16)(rng);
      const KeyBox b = random_box(t, rng, 40 << (16 - depth) > 400 ? 400 : 40 << (16 - depth));
      query::RegionOptions opt;
      opt.depth = int(depth);
      opt.include_free = q % 2 == 0;
      std::set<RegionEntry> got;
      for (const query::RegionVoxel& v : query::extract_region(t, b, opt)) {
        got.emplace(v.lo[0], v.lo[1], v.lo[2], v.depth, int(v.state));
        EXPECT_EQ(v.center, t.keyToCoord(v.lo, v.depth)) << "center";
      }
      const std::set<RegionEntry> want = brute_region(t, b, depth, opt.include_free);
      ASSERT_EQ(got, want) << describe(m.name, b) << " depth " << depth;
      nonempty += !want.empty();
      // Wrong variant: OctoMap's bbx iterator as is (it also yields nodes just below min).
      size_t raw = 0;
      for (auto it = t.begin_leafs_bbx(b.min, b.max, depth), end = t.end_leafs_bbx(); it != end; ++it)
        raw += opt.include_free || t.isNodeOccupied(*it);
      mutant_disagrees += raw != want.size();
    }
    EXPECT_GT(nonempty, 100) << m.name;
    EXPECT_GT(mutant_disagrees, 10) << m.name;
  }
}

TEST(RegionQuery, RefusesTooManyVoxelsAndBadDepth) {
  const octomap::OcTree& t = *query_test_maps()[1].tree;
  KeyBox all;
  all.min = octomap::OcTreeKey(0, 0, 0);
  all.max = octomap::OcTreeKey(65535, 65535, 65535);
  query::RegionOptions opt;
  opt.include_free = true;
  opt.max_voxels = 10;
  EXPECT_THROW(query::extract_region(t, all, opt), query::QueryError);
  opt.max_voxels = 1'000'000;
  opt.depth = 17;
  EXPECT_THROW(query::extract_region(t, all, opt), query::QueryError);
}

}  // namespace
}  // namespace ort::test
