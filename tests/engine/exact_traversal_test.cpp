// The exact CPU reference: its sweep finds what a brute-force scan of the box finds, with
// the same closed-box predicate; and it contains OctoMap's walk for ordinary rays.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "core/exact_traversal.h"

namespace ort {
namespace {

std::set<std::array<int, 3>> brute_force(const octomap::point3d& o, const octomap::point3d& e, double res) {
  const double a[3] = {o.x(), o.y(), o.z()}, b[3] = {e.x(), e.y(), e.z()};
  std::set<std::array<int, 3>> s;
  int lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = int(std::floor(std::min(a[i], b[i]) / res)) + 32768 - 2;
    hi[i] = int(std::floor(std::max(a[i], b[i]) / res)) + 32768 + 2;
  }
  for (int x = lo[0]; x <= hi[0]; ++x)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int z = lo[2]; z <= hi[2]; ++z) {
        const int k[3] = {x, y, z};
        if (segment_touches_voxel(a, b, k, res)) s.insert({x, y, z});
      }
  return s;
}

std::set<std::array<int, 3>> swept(const octomap::point3d& o, const octomap::point3d& e, double res) {
  std::vector<octomap::OcTreeKey> keys;
  exact_ray_keys(o, e, res, keys);
  std::set<std::array<int, 3>> s;
  for (const auto& k : keys) EXPECT_TRUE(s.insert({k[0], k[1], k[2]}).second) << "duplicate key";
  return s;
}

TEST(ExactTraversal, SweepEqualsBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_int_distribution<int> g(-8, 8);
  const double res = 0.1;
  for (int i = 0; i < 3000; ++i) {
    octomap::point3d o(u(rng), u(rng), u(rng)), e(u(rng), u(rng), u(rng));
    if (i % 3 == 0) {  // on voxel faces, edges and corners: grid coordinates
      o = octomap::point3d(g(rng) * 0.1f, g(rng) * 0.1f, u(rng));
      e = octomap::point3d(g(rng) * 0.1f, o.y(), g(rng) * 0.1f);
    }
    if (i % 7 == 0) e = o;  // zero length
    ASSERT_EQ(swept(o, e, res), brute_force(o, e, res)) << o << " -> " << e;
  }
}

TEST(ExactTraversal, RayAlongAFaceTouchesBothSides) {
  // y = 0 is a face between key 32767 and 32768: both rows are touched.
  const auto s = swept({0.05f, 0.0f, 0.05f}, {0.95f, 0.0f, 0.05f}, 0.1);
  EXPECT_TRUE(s.count({32768, 32767, 32768}));
  EXPECT_TRUE(s.count({32768, 32768, 32768}));
  EXPECT_EQ(s.size(), 20u);
}

TEST(ExactTraversal, ContainsOctomapWalk) {
  octomap::OcTree tree(0.1);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  for (int i = 0; i < 2000; ++i) {
    const octomap::point3d o(u(rng), u(rng), u(rng)), e(u(rng), u(rng), u(rng));
    octomap::KeyRay ray;
    ASSERT_TRUE(tree.computeRayKeys(o, e, ray));
    const auto s = swept(o, e, 0.1);
    for (const auto& k : ray) EXPECT_TRUE(s.count({k[0], k[1], k[2]})) << o << " -> " << e;
  }
}

}  // namespace
}  // namespace ort
