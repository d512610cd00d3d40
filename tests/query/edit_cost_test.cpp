// The cost of a clear, estimated before it starts (query/edit_cost.h): the count of straddling
// cubes against brute force, the estimate against what the clear then adds on the real maps,
// and the refusals the daemon's bounds rest on (a huge misaligned box, a walk cut at its bound).
#include <gtest/gtest.h>

#include <random>

#include "brute_force.h"
#include "query/edit_cost.h"
#include "query/map_edit.h"
#include "query_test_maps.h"

namespace ort::test {
namespace {

using query::ClearTo;
using query::KeyBox;
using query::NodeCube;
using query::Unknown;

constexpr query::EditBounds kUnbounded{int64_t(1) << 60, int64_t(1) << 60};

int64_t brute_straddling(const NodeCube& cube, const KeyBox& box) {
  int64_t n = 0;
  for (int s = cube.side; s >= 2; s /= 2)
    for (int x = 0; x < cube.side; x += s)
      for (int y = 0; y < cube.side; y += s)
        for (int z = 0; z < cube.side; z += s) {
          NodeCube c;
          c.side = s;
          c.lo = octomap::OcTreeKey(cube.lo[0] + x, cube.lo[1] + y, cube.lo[2] + z);
          n += query::overlap_voxels(c, box) > 0 && !query::cube_inside(c, box);
        }
  return n;
}

TEST(EditCost, StraddlingCubesEqualBruteForce) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> u(0, 80);
  for (int q = 0; q < 300; ++q) {
    NodeCube cube;
    cube.side = 32;
    cube.lo = octomap::OcTreeKey(1024, 2048, 4096);
    KeyBox b;
    for (int a = 0; a < 3; ++a) {
      int lo = cube.lo[a] - 24 + u(rng), hi = lo + u(rng) / 2;
      b.min[a] = octomap::key_type(lo), b.max[a] = octomap::key_type(hi);
    }
    ASSERT_EQ(query::straddling_cubes(cube, b), brute_straddling(cube, b)) << q;
  }
}

TEST(EditCost, TheEstimateBoundsWhatTheClearAdds) {
  std::mt19937 rng(44);
  for (const NamedMap& m : query_test_maps()) {
    int64_t added = 0;
    for (int q = 0; q < 12; ++q) {
      const ClearTo to = q % 3 == 0 ? ClearTo::kUnknown : ClearTo::kFree;
      const Unknown unknown = q % 3 == 1 ? Unknown::kMarked : Unknown::kKept;
      const KeyBox b = random_box(*m.tree, rng, 400);
      octomap::OcTree t(*m.tree);
      const query::EditCost cost = query::estimate_clear_box(t, b, to, unknown, kUnbounded);
      ASSERT_FALSE(cost.over);
      const auto before = static_cast<int64_t>(t.size());
      query::clear_box(t, b, to, unknown);
      const int64_t grew = static_cast<int64_t>(t.size()) - before;
      EXPECT_LE(grew, cost.new_nodes) << m.name << " q" << q;
      EXPECT_GT(cost.work, 0) << m.name << " q" << q;
      added += std::max<int64_t>(0, grew);
    }
    EXPECT_GT(added, 0) << m.name;  // the boxes split leaves: the check above is not vacuous
  }
}

// A box over nearly the whole key space, misaligned by one voxel: marking its unknown space
// free would split cubes along its whole surface from the root down (~10^10 nodes). The
// estimate says so without walking anything; on known space only, the same box costs what the
// map holds, and is within the default bounds.
TEST(EditCost, AHugeMisalignedBoxIsOverItsBoundUnlessItClearsKnownSpace) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  KeyBox b;
  b.min = octomap::OcTreeKey(1, 1, 1);
  b.max = octomap::OcTreeKey(65534, 65534, 65534);
  const query::EditBounds defaults{1'000'000, 16'000'000};  // the server's
  const query::EditCost marked = query::estimate_clear_box(t, b, ClearTo::kFree, Unknown::kMarked, defaults);
  EXPECT_TRUE(marked.over);
  EXPECT_GT(marked.new_nodes, int64_t(10'000'000'000));
  EXPECT_EQ(marked.work, 0);  // refused from the box alone
  const query::EditCost known = query::estimate_clear_box(t, b, ClearTo::kFree, Unknown::kKept, defaults);
  EXPECT_FALSE(known.over);
  EXPECT_GE(known.work, static_cast<int64_t>(t.size()) - 100);  // every node of the map, but the border's
}

TEST(EditCost, TheWalkStopsAtItsWorkBound) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  KeyBox all;
  all.min = octomap::OcTreeKey(0, 0, 0);
  all.max = octomap::OcTreeKey(65535, 65535, 65535);
  const query::EditBounds small{1'000'000, 1000};
  for (ClearTo to : {ClearTo::kFree, ClearTo::kUnknown}) {
    const query::EditCost c = query::estimate_clear_box(t, all, to, Unknown::kKept, small);
    EXPECT_TRUE(c.over);
    EXPECT_LE(c.work, 1000 + 17);
  }
  ASSERT_GT(t.size(), 1000u);
}

}  // namespace
}  // namespace ort::test
