// The map frame's transforms (core/map_frame.h) give OctoMap's own transforms bit for bit:
// the parallel one of a whole cloud, the inlined one of a pose, the one in lanes.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/map_frame.h"

namespace ort {
namespace {

TEST(MapFrame, ParallelTransformEqualsPointcloudTransformBitForBit) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-30.0f, 30.0f);
  octomap::Pointcloud pc;
  for (int i = 0; i < 100000; ++i) pc.push_back(u(rng), u(rng), u(rng));
  const octomap::pose6d pose(1.5, -2.25, 0.3, 0.1, -0.2, 2.9);
  octomap::Pointcloud reference(pc), ours(pc);
  reference.transform(pose);
  transform_to_map_frame(ours, pose, 7);
  ASSERT_EQ(ours.size(), reference.size());
  for (size_t i = 0; i < pc.size(); ++i) {
    ASSERT_EQ(ours[i].x(), reference[i].x());
    ASSERT_EQ(ours[i].y(), reference[i].y());
    ASSERT_EQ(ours[i].z(), reference[i].z());
  }
}

// The inlined transform (MapFrameTransform) against Pose6D::transform, bit for bit (memcmp, so
// that -0.0 and NaN payloads count): random poses and identity / half turns, points from
// sub-millimetre to kilometres, zeros, and non-finite coordinates.
TEST(MapFrame, InlinedTransformEqualsPose6dTransformBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-3.2, 3.2), shift(-500.0, 500.0);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), mag(-3.0f, 3.5f);
  std::vector<octomap::pose6d> poses = {octomap::pose6d(0, 0, 0, 0, 0, 0), octomap::pose6d(1, 2, 3, 3.14159265, 0, 0),
                                        octomap::pose6d(-1, 0, 0.5, 0, 0, -3.14159265)};
  for (int i = 0; i < 40; ++i)
    poses.emplace_back(shift(rng), shift(rng), shift(rng), angle(rng), angle(rng), angle(rng));
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<octomap::point3d> points = {{0, 0, 0}, {-0.0f, 0, -0.0f}, {inf, 1, 2}, {1, nan, 3}, {-inf, -inf, 0}};
  for (int i = 0; i < 20000; ++i) {
    const float scale = std::pow(10.0f, mag(rng));
    points.emplace_back(u(rng) * scale, u(rng) * scale, u(rng) * scale);
  }
  for (const auto& pose : poses) {
    const MapFrameTransform transform(pose);
    for (const auto& p : points) {
      const octomap::point3d a = pose.transform(p), b = transform(p);
      const float fa[3] = {a.x(), a.y(), a.z()}, fb[3] = {b.x(), b.y(), b.z()};
      ASSERT_EQ(std::memcmp(fa, fb, sizeof fa), 0) << p << " under " << pose << ": " << a << " vs " << b;
    }
  }
}

// MapFrameTransform::apply (eight points at a time in AVX2 lanes where the CPU has it; in
// place and from x y z floats into another array) against operator() point by point, bit for
// bit (memcmp): 23 poses, every count 0-17 (the
// lanes' remainders) and 20,000 points with zeros, -0.0, inf and NaN in every lane position.
TEST(MapFrame, TransformInLanesEqualsPointByPointBitForBit) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> angle(-3.2, 3.2), shift(-500.0, 500.0);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), mag(-3.0f, 3.5f);
  std::vector<octomap::pose6d> poses = {octomap::pose6d(0, 0, 0, 0, 0, 0), octomap::pose6d(1, 2, 3, 3.14159265, 0, 0),
                                        octomap::pose6d(-1, 0, 0.5, 0, 0, -3.14159265)};
  for (int i = 0; i < 20; ++i)
    poses.emplace_back(shift(rng), shift(rng), shift(rng), angle(rng), angle(rng), angle(rng));
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const octomap::point3d odd[] = {{0, 0, 0},   {-0.0f, 0, -0.0f}, {inf, 1, 2},
                                  {1, nan, 3}, {-inf, -inf, 0},   {0, 0, -0.0f}};
  std::vector<octomap::point3d> points;
  for (int i = 0; i < 20000; ++i) {
    const float scale = std::pow(10.0f, mag(rng));
    points.emplace_back(u(rng) * scale, u(rng) * scale, u(rng) * scale);
    if (i % 7 == 3) points.back() = odd[(i / 7) % 6];
  }
  for (const auto& pose : poses) {
    const MapFrameTransform transform(pose);
    for (size_t n = 0; n <= points.size(); n = n < 17 ? n + 1 : points.size() + (n == points.size())) {
      std::vector<octomap::point3d> lanes(points.begin(), points.begin() + n), one_by_one(lanes), apart(n);
      transform.apply(lanes.data(), n);
      transform.apply(one_by_one.data(), n, false);
      transform.apply(&points[0](0), apart.data(), n);  // from x y z floats into another array
      for (size_t i = 0; i < n; ++i) {
        const octomap::point3d expected = transform(points[i]);
        ASSERT_EQ(std::memcmp(&one_by_one[i], &expected, sizeof expected), 0) << i;
        ASSERT_EQ(std::memcmp(&apart[i], &expected, sizeof expected), 0) << i;
        ASSERT_EQ(std::memcmp(&lanes[i], &expected, sizeof expected), 0)
            << points[i] << " under " << pose << ": " << lanes[i] << " vs " << expected << " (point " << i << " of "
            << n << ")";
      }
    }
  }
}

}  // namespace
}  // namespace ort
