// The distance transform equals a brute-force nearest-obstacle search on real maps: every
// cell of sampled boxes (distances and gradients), points, paths; unknown space as free and
// as occupied; the map's resolution and coarser cells. A variant without the padding (the
// obstacles outside the box ignored) must disagree, or the comparison could not fail.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "brute_distance.h"
#include "distance/distance_queries.h"
#include "distance/squared_edt.h"
#include "query/query_test_maps.h"

namespace ort::test {
namespace {

using distance::UnknownAs;
constexpr int64_t kOrigin = 32768;

const std::vector<octomap::OcTreeKey>& occupied_keys(const octomap::OcTree& t) {
  static std::map<const octomap::OcTree*, std::vector<octomap::OcTreeKey>> known;
  auto& keys = known[&t];
  if (keys.empty())
    for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it)
      if (t.isNodeOccupied(*it)) keys.push_back(it.getKey());
  return keys;
}

// Metric coordinate of the centre of finest key k (OctoMap's keyToCoord at depth 16).
double key_center(const octomap::OcTree& t, int64_t k) { return (double(k - kOrigin) + 0.5) * t.getResolution(); }

float clamp_distance(uint32_t sq, double cs, double max) {
  return sq == distance::kNoObstacle ? float(max) : float(std::min(std::sqrt(double(sq)) * cs, max));
}

struct Sample {
  std::array<int64_t, 3> lo{}, n{};  // absolute cells of the box
};

Sample box_near_obstacle(const octomap::OcTree& t, std::mt19937& rng, int m) {
  const auto& keys = occupied_keys(t);
  const auto& key = keys[std::uniform_int_distribution<size_t>(0, keys.size() - 1)(rng)];
  Sample s;
  for (int a = 0; a < 3; ++a) {
    s.n[a] = std::uniform_int_distribution<int>(6, 16)(rng);
    s.lo[a] = int64_t(key[a]) / m - std::uniform_int_distribution<int>(0, int(s.n[a]) + 4)(rng);
  }
  return s;
}

struct Tally {
  int64_t cells = 0, wrong = 0, wrong_unpadded = 0, obstacles_far = 0;
};

void check_box(const octomap::OcTree& t, const Sample& s, int m, UnknownAs unknown, double max, Tally& tally) {
  const double cs = t.getResolution() * m;
  const int reach = int(std::ceil(max / cs));
  distance::DistanceOptions opt;
  opt.max_distance = max, opt.cell_voxels = m, opt.unknown = unknown;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = key_center(t, s.lo[a] * m), hi[a] = key_center(t, (s.lo[a] + s.n[a]) * m - 1);
  const distance::BoxRead read = distance::read_box(t, lo, hi, opt, {});
  const distance::BoxDistances box = distance::answer_box(read, distance::cpu_edt(2), true);
  for (int a = 0; a < 3; ++a) ASSERT_EQ(box.cells.key_lo[a], s.lo[a] * m);
  ASSERT_EQ(box.cells.dims.nx, s.n[0]);
  ASSERT_EQ(box.cells.dims.nz, s.n[2]);
  // Same answer with one worker.
  ASSERT_EQ(distance::answer_box(read, distance::cpu_edt(1), false).squared, box.squared);

  // Brute force over the box grown by the reach and one more cell (the gradient's neighbours).
  std::array<int64_t, 3> blo, bn;
  for (int a = 0; a < 3; ++a) blo[a] = s.lo[a] - reach - 1, bn[a] = s.n[a] + 2 * reach + 2;
  const BruteObstacles o = brute_obstacles(t, blo, bn, m, unknown);
  // The wrong variant: the box alone, no obstacles outside it.
  distance::CellBox inner = box.cells;
  const distance::OccupancyGrid bare = distance::read_occupancy(t, inner, unknown);
  std::vector<uint32_t> unpadded(bare.occupied.size());
  distance::squared_edt(bare.occupied, inner.dims, unpadded, 1);

  size_t c = 0;
  for (int64_t k = 0; k < s.n[2]; ++k)
    for (int64_t j = 0; j < s.n[1]; ++j)
      for (int64_t i = 0; i < s.n[0]; ++i, ++c) {
        const std::array<int64_t, 3> cell{s.lo[0] + i, s.lo[1] + j, s.lo[2] + k};
        uint32_t want = brute_squared(o, cell, reach);
        if (want != distance::kNoObstacle && std::sqrt(double(want)) * cs > max) want = distance::kNoObstacle;
        ++tally.cells;
        if (box.squared[c] != want) {
          if (++tally.wrong < 10)
            ADD_FAILURE() << "cell " << cell[0] << "," << cell[1] << "," << cell[2] << ": " << box.squared[c]
                          << " != brute " << want;
          continue;
        }
        uint32_t bare_sq = unpadded[c];
        if (bare_sq != distance::kNoObstacle && std::sqrt(double(bare_sq)) * cs > max) bare_sq = distance::kNoObstacle;
        if (bare_sq != want) ++tally.wrong_unpadded;
        for (int a = 0; a < 3; ++a) {
          std::array<int64_t, 3> up = cell, down = cell;
          ++up[a], --down[a];
          const float du = clamp_distance(brute_squared(o, up, reach), cs, max);
          const float dd = clamp_distance(brute_squared(o, down, reach), cs, max);
          const float g = float((du - dd) / (2 * cs));
          if (std::abs(box.gradient[3 * c + a] - g) > 1e-5f && ++tally.wrong < 10)
            ADD_FAILURE() << "gradient " << a << " at " << cell[0] << "," << cell[1] << "," << cell[2] << ": "
                          << box.gradient[3 * c + a] << " != " << g;
        }
      }
}

TEST(DistanceExactness, BoxCellsEqualBruteForceOnRealMaps) {
  std::mt19937 rng(27);
  Tally tally;
  for (const NamedMap& map : query_test_maps()) {
    SCOPED_TRACE(map.name);
    ASSERT_FALSE(occupied_keys(*map.tree).empty());
    for (int m : {1, 2})
      for (UnknownAs unknown : {UnknownAs::kFree, UnknownAs::kOccupied})
        for (int b = 0; b < 3; ++b) {
          const double cs = map.tree->getResolution() * m;
          const double max = (std::uniform_int_distribution<int>(2, 7)(rng) + 0.45) * cs;  // never a tie
          check_box(*map.tree, box_near_obstacle(*map.tree, rng, m), m, unknown, max, tally);
        }
  }
  EXPECT_EQ(tally.wrong, 0) << "of " << tally.cells << " cells";
  EXPECT_GT(tally.cells, 20000);
  // Obstacles outside the box matter: without the padding, answers differ.
  EXPECT_GT(tally.wrong_unpadded, 0);
}

TEST(DistanceExactness, PointsEqualBruteForceAlsoWhenSpreadOverBlocks) {
  std::mt19937 rng(2027);
  for (const NamedMap& map : query_test_maps()) {
    SCOPED_TRACE(map.name);
    const octomap::OcTree& t = *map.tree;
    const double res = t.getResolution(), max = 6.45 * res;
    const int reach = 7;
    for (UnknownAs unknown : {UnknownAs::kFree, UnknownAs::kOccupied}) {
      // Two clusters of points around two obstacles, each a cube of 24 voxels.
      const auto& keys = occupied_keys(t);
      std::vector<float> xyz;
      std::vector<std::array<int64_t, 3>> cells;
      std::vector<BruteObstacles> brute;
      std::vector<int> cluster_of;
      for (int cl = 0; cl < 2; ++cl) {
        const auto key = keys[std::uniform_int_distribution<size_t>(0, keys.size() - 1)(rng)];
        std::array<int64_t, 3> lo, n{24 + 2 * reach, 24 + 2 * reach, 24 + 2 * reach};
        for (int a = 0; a < 3; ++a) lo[a] = int64_t(key[a]) - 12 - reach;
        brute.push_back(brute_obstacles(t, lo, n, 1, unknown));
        for (int p = 0; p < 300; ++p) {
          std::array<int64_t, 3> c;
          for (int a = 0; a < 3; ++a) {
            c[a] = int64_t(key[a]) + std::uniform_int_distribution<int>(-12, 11)(rng);
            // Anywhere inside the voxel, faces included.
            const double f = std::uniform_int_distribution<int>(0, 3)(rng) == 0
                                 ? 0.0
                                 : std::uniform_real_distribution<double>(0.01, 0.99)(rng);
            xyz.push_back(float((double(c[a] - kOrigin) + f) * res));
          }
          cells.push_back(c), cluster_of.push_back(cl);
        }
      }
      for (int64_t single : {int64_t(8'000'000), int64_t(1)}) {  // one grid; one grid per block
        distance::DistanceLimits lim;
        lim.single_grid_cells = single;
        distance::DistanceOptions opt;
        opt.max_distance = max, opt.unknown = unknown;
        const auto read = distance::read_points(t, xyz, opt, lim);
        EXPECT_EQ(read.grids.size() > 1, single == 1);
        const auto got = distance::answer_points(read, distance::cpu_edt(2));
        ASSERT_EQ(got.size(), cells.size());
        int wrong = 0;
        for (size_t p = 0; p < got.size(); ++p) {
          // The point's key may differ from the cell drawn (float rounding on a face): use its own key.
          const octomap::OcTreeKey k = t.coordToKey(octomap::point3d(xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]));
          const std::array<int64_t, 3> c{k[0], k[1], k[2]};
          const float want = clamp_distance(brute_squared(brute[size_t(cluster_of[p])], c, reach), res, max);
          if (got[p].distance != want && ++wrong < 5)
            ADD_FAILURE() << "point " << p << ": " << got[p].distance << " != brute " << want;
          for (int a = 0; a < 3; ++a) EXPECT_FLOAT_EQ(got[p].cell_center[a], float(key_center(t, c[a])));
        }
        EXPECT_EQ(wrong, 0);
      }
    }
  }
}

TEST(DistanceExactness, PathClearanceIsTheMinimumOverItsSamples) {
  const NamedMap& map = query_test_maps()[0];
  const octomap::OcTree& t = *map.tree;
  const auto& keys = occupied_keys(t);
  const auto k0 = keys[keys.size() / 3], k1 = keys[keys.size() / 3 + 50];
  const double v[] = {key_center(t, k0[0]) + 0.3, key_center(t, k0[1]) - 0.4, key_center(t, k0[2]),
                      key_center(t, k1[0]),       key_center(t, k1[1]) + 0.5, key_center(t, k1[2]) + 0.2,
                      key_center(t, k1[0]) + 1.0, key_center(t, k1[1]) + 0.5, key_center(t, k1[2]) + 0.2};
  distance::DistanceOptions opt;
  opt.max_distance = 1.05;
  const auto read = distance::read_path(t, v, opt, {});
  const auto clearance = distance::answer_path(read, distance::cpu_edt(2));
  ASSERT_GT(clearance.num_samples, 3);
  const auto each = distance::answer_points(read.points, distance::cpu_edt(1));
  float lowest = each[0].distance;
  for (const auto& d : each) lowest = std::min(lowest, d.distance);
  EXPECT_EQ(clearance.min_distance, lowest);
  EXPECT_EQ(each[size_t(clearance.min_sample)].distance, lowest);
  // Samples at most one resolution apart along the path.
  for (size_t i = 1; i < read.arc_length.size(); ++i)
    EXPECT_LE(read.arc_length[i] - read.arc_length[i - 1], t.getResolution() + 1e-9);
  EXPECT_NEAR(read.arc_length.back(), std::hypot(v[3] - v[0], v[4] - v[1], v[5] - v[2]) + 1.0, 1e-9);
}

TEST(DistanceExactness, EnvelopeEqualsBruteForceOnRandomLines) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = std::uniform_int_distribution<int>(1, 40)(rng);
    std::vector<uint32_t> f(n), d(n);
    std::vector<int32_t> v(n), z(n);
    for (auto& x : f)
      x = std::uniform_int_distribution<int>(0, 3)(rng) == 0
              ? distance::kNoObstacle
              : uint32_t(std::uniform_int_distribution<int>(0, 300)(rng));
    distance::envelope_1d(f.data(), n, d.data(), v.data(), z.data());
    for (int x = 0; x < n; ++x) {
      uint32_t want = distance::kNoObstacle;
      for (int q = 0; q < n; ++q)
        if (f[q] != distance::kNoObstacle) want = std::min(want, uint32_t((x - q) * (x - q)) + f[q]);
      ASSERT_EQ(d[x], want) << "trial " << trial << " x " << x;
    }
  }
}

TEST(DistanceLimits, RefusalsSayWhichBound) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  distance::DistanceOptions opt;
  const float far[] = {1e6f, 0, 0};
  EXPECT_THROW(distance::read_points(t, far, opt, {}), distance::DistanceError);
  opt.max_distance = 0;
  EXPECT_THROW(distance::read_points(t, std::span<const float>(), opt, {}), distance::DistanceError);
  opt.max_distance = 2;
  distance::DistanceLimits lim;
  lim.max_grid_cells = 1000;
  const double lo[] = {0, 0, 0}, hi[] = {1, 1, 1};
  try {
    distance::read_box(t, lo, hi, opt, lim);
    ADD_FAILURE() << "no refusal";
  } catch (const distance::DistanceError& e) {
    EXPECT_NE(std::string(e.what()).find("at most 1000"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ort::test
