// Point and ray queries give exactly OctoMap's answers (search at a depth + isNodeOccupied;
// castRay) for thousands of random queries on real maps, and a wrong rule is caught.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "query/point_query.h"
#include "query/ray_query.h"
#include "query_test_maps.h"

namespace ort::test {
namespace {

using query::VoxelState;

TEST(PointQuery, SameAsOctomapSearchAtEveryDepth) {
  std::mt19937 rng(11);
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    int counts[3] = {0, 0, 0}, wrong_depth_disagrees = 0;
    for (int q = 0; q < 4000; ++q) {
      const octomap::point3d p = random_point(t, rng);
      const int depth = q % 4 == 0 ? 0 : std::uniform_int_distribution<int>(1, 16)(rng);
      const query::PointAnswer a = query::query_point(t, p, depth);
      // search(p, depth) (its out-of-range branch prints an error and returns null).
      octomap::OcTreeKey k;
      const octomap::OcTreeNode* n = t.coordToKeyChecked(p, k) ? t.search(p, depth) : nullptr;
      ASSERT_EQ(a.state, !n                    ? VoxelState::kUnknown
                         : t.isNodeOccupied(n) ? VoxelState::kOccupied
                                               : VoxelState::kFree)
          << m.name << " point " << p << " depth " << depth;
      EXPECT_EQ(a.probability, n ? float(n->getOccupancy()) : -1.0f);
      counts[int(a.state)]++;
      // Mutation check: ignoring the depth (always the finest level) is a different rule.
      if (query::query_point(t, p, 0).state != a.state) ++wrong_depth_disagrees;
    }
    // The inputs reach every state, so a rule error on any of them would show.
    EXPECT_GT(counts[0], 100) << m.name;
    EXPECT_GT(counts[1], 30) << m.name;
    EXPECT_GT(counts[2], 20) << m.name;
    EXPECT_GT(wrong_depth_disagrees, 0) << m.name << ": the depth rule is not exercised";
  }
}

TEST(PointQuery, BatchKeepsInputOrderAndRefusesBadDepth) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  std::mt19937 rng(5);
  std::vector<float> xyz;
  for (int i = 0; i < 300; ++i) {
    const octomap::point3d p = random_point(t, rng);
    xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  }
  const auto answers = query::query_points(t, xyz, 0);
  ASSERT_EQ(answers.size(), 300u);
  for (size_t i = 0; i < answers.size(); ++i)
    EXPECT_EQ(answers[i].state,
              query::query_point(t, octomap::point3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2])).state);
  EXPECT_THROW(query::query_points(t, xyz, 17), query::QueryError);
  EXPECT_THROW(query::query_points(t, xyz, -1), query::QueryError);
  EXPECT_EQ(query::query_point(t, octomap::point3d(NAN, 0, 0)).state, VoxelState::kUnknown);
  // Far outside the key range (where OctoMap's own conversion is undefined): unknown, as
  // search() answers for any point outside the map.
  EXPECT_EQ(query::query_point(t, octomap::point3d(-3e38f, 0, 0)).state, VoxelState::kUnknown);
  EXPECT_EQ(query::query_point(t, octomap::point3d(0, 1e20f, 0)).state, VoxelState::kUnknown);
}

// Rays along the axes, in voxel faces (origins on voxel boundaries, axis or face-diagonal
// directions), and random ones, with and without ignore_unknown and max range.
octomap::point3d ray_direction(std::mt19937& rng) {
  const int kind = std::uniform_int_distribution<int>(0, 3)(rng);
  std::uniform_int_distribution<int> sign(0, 1), axis(0, 2);
  float d[3] = {0, 0, 0};
  if (kind == 0) {
    d[axis(rng)] = sign(rng) ? 1.f : -1.f;
  } else if (kind == 1) {
    const int a = axis(rng);
    d[a] = sign(rng) ? 1.f : -1.f;
    d[(a + 1) % 3] = sign(rng) ? 1.f : -1.f;
  } else {
    std::normal_distribution<float> n(0, 1);
    for (float& v : d) v = n(rng);
  }
  return octomap::point3d(d[0], d[1], d[2]);
}

TEST(RayQuery, SameAsOctomapCastRay) {
  std::mt19937 rng(12);
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    int hits = 0, unknown_ends = 0, ignore_disagrees = 0;
    for (int q = 0; q < 3000; ++q) {
      octomap::point3d o = random_point(t, rng);
      // Most rays start in known free space, where a planner casts them.
      if (q % 3 != 0) {
        for (auto it = t.begin_leafs(); it != t.end_leafs(); ++it)
          if (!t.isNodeOccupied(*it) && std::uniform_int_distribution<int>(0, 200)(rng) == 0) {
            o = it.getCoordinate();
            break;
          }
      }
      const octomap::point3d d = ray_direction(rng);
      query::RayBatchOptions opt;
      opt.ignore_unknown = q % 2 == 0;
      opt.max_range = std::uniform_real_distribution<double>(0.5, 20.0)(rng);
      const query::RayAnswer a = query::cast_ray(t, o, d, opt);
      octomap::point3d end;
      octomap::OcTreeKey key;
      const bool in_map = t.coordToKeyChecked(o, key);
      const bool hit = in_map && t.castRay(o, d, end, opt.ignore_unknown, opt.max_range);
      ASSERT_EQ(a.hit, hit) << m.name << " ray " << o << " -> " << d;
      if (in_map) {
        ASSERT_EQ(a.end, end) << m.name << " ray " << o << " -> " << d;
      }
      if (a.hit) {
        EXPECT_EQ(a.end_state, VoxelState::kOccupied);
      }
      hits += a.hit;
      unknown_ends += a.end_state == VoxelState::kUnknown;
      // Mutation check: the ignore_unknown flag changes answers on these rays.
      query::RayBatchOptions flipped = opt;
      flipped.ignore_unknown = !opt.ignore_unknown;
      if (query::cast_ray(t, o, d, flipped).end != a.end) ++ignore_disagrees;
    }
    EXPECT_GT(hits, 100) << m.name;
    EXPECT_GT(unknown_ends, 100) << m.name;
    EXPECT_GT(ignore_disagrees, 50) << m.name;
  }
}

TEST(RayQuery, RefusesRaysCastRayCannotCast) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  EXPECT_THROW(query::cast_ray(t, {0, 0, 0}, {0, 0, 0}, {}), query::QueryError);
  EXPECT_THROW(query::cast_ray(t, {NAN, 0, 0}, {1, 0, 0}, {}), query::QueryError);
  EXPECT_THROW(query::cast_ray(t, {0, 0, 0}, {1, INFINITY, 0}, {}), query::QueryError);
  EXPECT_THROW(query::cast_ray(t, {0, 0, 0}, {1e30f, 1e30f, 0}, {}), query::QueryError);  // norm overflows
  EXPECT_TRUE(query::cast_ray(t, {0, 0, 0}, {1e15f, 1e15f, 0}, {}).end.norm() >= 0.f);    // fine: castRay normalizes
  const query::RayAnswer far = query::cast_ray(t, {1e6f, 0, 0}, {1, 0, 0}, {});
  EXPECT_FALSE(far.hit);
  EXPECT_EQ(far.end, octomap::point3d(1e6f, 0, 0));
  EXPECT_EQ(far.end_state, VoxelState::kUnknown);
}

TEST(RayQuery, WalkBoundIsTheKeyRangeForNonFiniteFields) {
  // A query's direction or range may be inf or NaN (the fuzzer found inf/inf = NaN cast to an
  // integer); the bound is then the whole key range, and a finite ray's bound stays below it.
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  const uint64_t edge = 3ull << t.getTreeDepth();
  query::RayBatchOptions opt;
  opt.max_range = 5;
  EXPECT_EQ(query::ray_walk_bound(t, {INFINITY, 1, 0}, opt), edge);
  EXPECT_EQ(query::ray_walk_bound(t, {NAN, 1, 0}, opt), edge);
  EXPECT_EQ(query::ray_walk_bound(t, {1e30f, 1e30f, 1e30f}, opt), edge);  // the norm overflows in float
  opt.max_range = INFINITY;
  EXPECT_EQ(query::ray_walk_bound(t, {1, 0, 0}, opt), edge);
  opt.max_range = NAN;
  EXPECT_EQ(query::ray_walk_bound(t, {1, 0, 0}, opt), edge);
  opt.max_range = 1;
  EXPECT_LT(query::ray_walk_bound(t, {1, 0, 0}, opt), edge);
}

}  // namespace
}  // namespace ort::test
