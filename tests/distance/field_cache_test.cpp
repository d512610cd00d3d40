// The field cache (distance/field_cache.h) answers what a fresh EDT answers: a real map's box
// read once, then its grid changed step by step (single cells, clusters, two far apart, a
// block) as scans change a map; after every step the box's distances and gradients from the
// updated field equal those of the field computed whole. The changes must show in the answer
// (a cache that kept its old field would then fail), and some updates must be partial.
// Points read through the cached box answer as they do from their own grid.
#include <gtest/gtest.h>

#include <random>

#include "distance/distance_queries.h"
#include "distance/field_cache.h"
#include "distance/squared_edt.h"
#include "query/query_test_maps.h"

namespace ort::test {
namespace {

using distance::UnknownAs;
constexpr int64_t kOrigin = 32768;

double key_center(const octomap::OcTree& t, int64_t k) { return (double(k - kOrigin) + 0.5) * t.getResolution(); }

// A box of about 40 x 36 x 24 cells around an occupied voxel of the map.
void box_around_obstacle(const octomap::OcTree& t, int m, double lo[3], double hi[3]) {
  std::array<int64_t, 3> key{};
  int seen = 0;
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it)
    if (t.isNodeOccupied(*it) && ++seen == 200) {
      for (int a = 0; a < 3; ++a) key[a] = it.getKey()[a];
      break;
    }
  const int64_t n[3] = {40, 36, 24};
  for (int a = 0; a < 3; ++a) {
    lo[a] = key_center(t, key[a] - n[a] / 2 * m);
    hi[a] = key_center(t, key[a] + n[a] / 2 * m - 1);
  }
}

void expect_same_box(const distance::BoxDistances& got, const distance::BoxDistances& want, int& wrong) {
  ASSERT_EQ(got.squared.size(), want.squared.size());
  for (size_t c = 0; c < got.squared.size(); ++c) {
    if (got.squared[c] != want.squared[c] && ++wrong < 5)
      ADD_FAILURE() << "cell " << c << ": " << got.squared[c] << " != fresh " << want.squared[c];
    for (int a = 0; a < 3; ++a)
      if (got.gradient[3 * c + a] != want.gradient[3 * c + a] && ++wrong < 5)
        ADD_FAILURE() << "gradient of cell " << c << ": " << got.gradient[3 * c + a] << " != fresh "
                      << want.gradient[3 * c + a];
  }
}

// Both update tests' set-up and step: a real map's box read once and cached (at `version`),
// its grid changed by the test; check() compares the cache's updated field with the field of
// the grid computed whole and counts the steps whose change moved the answer.
struct CachedBox {
  CachedBox(const octomap::OcTree& t, const distance::DistanceOptions& o, const distance::SquaredEdt& e,
            uint64_t version)
      : opt(o), edt(e), read(read_around_obstacle(t, o)), grid(read.grid) {
    cache.update(grid, edt, read.resolution, opt, version);
    before = fresh();
  }
  static distance::BoxRead read_around_obstacle(const octomap::OcTree& t, const distance::DistanceOptions& o) {
    double lo[3], hi[3];
    box_around_obstacle(t, o.cell_voxels, lo, hi);
    return distance::read_box(t, lo, hi, o, {});
  }
  distance::BoxDistances fresh() const {
    return distance::answer_box(read, distance::compute_field(grid, edt, read.resolution, opt), true);
  }
  void check(const distance::DistanceField& updated) {
    const distance::BoxDistances want = fresh();
    expect_same_box(distance::answer_box(read, updated, true), want, wrong);
    if (want.squared != before.squared) ++visible;
    before = std::move(want);
  }
  const distance::DistanceOptions opt;
  const distance::SquaredEdt& edt;
  const distance::BoxRead read;
  distance::FieldCache cache;
  distance::OccupancyGrid grid;  // the map's cells as the test changed them
  distance::BoxDistances before;
  int wrong = 0, visible = 0;
};

TEST(FieldCache, UpdatedFieldsAnswerAsFreshOnesOnARealMap) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  const auto edt = distance::cpu_edt(2);
  std::mt19937 rng(27);
  for (int m : {1, 2})
    for (UnknownAs unknown : {UnknownAs::kFree, UnknownAs::kOccupied}) {
      SCOPED_TRACE("cell_voxels " + std::to_string(m) + (unknown == UnknownAs::kFree ? " free" : " occupied"));
      distance::DistanceOptions opt;
      opt.max_distance = 6.45 * t.getResolution() * m, opt.cell_voxels = m, opt.unknown = unknown;
      CachedBox box(t, opt, edt, 0);
      distance::FieldCache& cache = box.cache;
      distance::OccupancyGrid& grid = box.grid;
      cache.update(grid, edt, box.read.resolution, opt);
      EXPECT_EQ(cache.stats().full, 1);
      EXPECT_EQ(cache.stats().unchanged, 1);
      const distance::GridDims d = grid.box.dims;
      auto cell = [&](int64_t i, int64_t j, int64_t k) -> uint8_t& {
        return grid.occupied[size_t((k * d.ny + j) * d.nx + i)];
      };
      auto random_cell = [&](int axis) { return std::uniform_int_distribution<int64_t>(0, (&d.nx)[axis] - 1)(rng); };
      for (int step = 0; step < 24; ++step) {
        const int kind = step % 4;  // one cell; a 3-cell cluster; two far apart; a 6-cell block
        const int clusters = kind == 2 ? 2 : 1, side = kind == 3 ? 6 : kind == 0 ? 1 : 3;
        for (int c = 0; c < clusters; ++c) {
          const int64_t x = random_cell(0), y = random_cell(1), z = random_cell(2);
          for (int64_t k = z; k < std::min<int64_t>(d.nz, z + side); ++k)
            for (int64_t j = y; j < std::min<int64_t>(d.ny, y + side); ++j)
              for (int64_t i = x; i < std::min<int64_t>(d.nx, x + side); ++i) cell(i, j, k) ^= 1;
        }
        box.check(cache.update(grid, edt, box.read.resolution, opt));
      }
      EXPECT_EQ(box.wrong, 0);
      EXPECT_GE(box.visible, 8) << "the changes must move the answer, or a cache that kept its field would pass";
      EXPECT_GE(cache.stats().partial, 12);
    }
}

// The same changes handed over as patches (the cells that changed, as the map's change lists
// say, with cells set to what they already were among them): the field equals a fresh one
// after every step; a patch from another state than the entry's is refused.
TEST(FieldCache, PatchedFieldsAnswerAsFreshOnesOnARealMap) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  const auto edt = distance::cpu_edt(2);
  std::mt19937 rng(41);
  distance::DistanceOptions opt;
  opt.max_distance = 6.45 * t.getResolution();
  CachedBox box(t, opt, edt, 7);
  distance::FieldCache& cache = box.cache;
  distance::OccupancyGrid& grid = box.grid;
  const distance::GridDims d = grid.box.dims;
  std::uniform_int_distribution<uint32_t> any_cell(0, uint32_t(d.cells() - 1));
  uint64_t version = 7;
  for (int step = 0; step < 16; ++step) {
    distance::GridPatch patch;
    patch.box = grid.box, patch.from = version, patch.to = ++version;
    const uint32_t at = any_cell(rng);
    for (int c = 0; c < (step % 3 == 0 ? 1 : 12); ++c) {  // one cell, or a run of 12 along x
      const uint32_t index = std::min<uint32_t>(uint32_t(d.cells() - 1), at + uint32_t(c));
      grid.occupied[index] ^= 1;
      patch.cells.push_back({index, grid.occupied[index]});
    }
    patch.cells.push_back({any_cell(rng), 0});  // a change back and forth within the patch
    patch.cells.back().occupied = grid.occupied[patch.cells.back().index];
    box.check(cache.update(patch, edt, opt));
  }
  EXPECT_EQ(box.wrong, 0);
  EXPECT_GE(box.visible, 6);
  EXPECT_EQ(cache.stats().patched, 16);
  EXPECT_GE(cache.stats().partial, 12);
  distance::GridPatch stale;
  stale.box = grid.box, stale.from = version - 1, stale.to = version + 1;
  EXPECT_THROW(cache.update(stale, edt, opt), distance::DistanceError);
}

TEST(FieldCache, PointsReadThroughTheCachedBoxAnswerAsFromTheirOwnGrid) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  const auto edt = distance::cpu_edt(2);
  distance::DistanceOptions opt;
  opt.max_distance = 6.45 * t.getResolution();
  double lo[3], hi[3];
  box_around_obstacle(t, 1, lo, hi);
  distance::BoxRead box = distance::read_box(t, lo, hi, opt, {});
  distance::FieldCache cache;
  const distance::CellBox cached = box.grid.box;
  cache.update(std::move(box.grid), edt, box.resolution, opt);
  std::mt19937 rng(5);
  std::vector<float> xyz;
  for (int p = 0; p < 300; ++p)
    for (int a = 0; a < 3; ++a) xyz.push_back(float(std::uniform_real_distribution<double>(lo[a], hi[a])(rng)));
  cache.will_hold(cached, opt, box.resolution, 0);
  auto cover = [&](const distance::CellBox& want) -> std::optional<distance::GridCover> {
    const auto c = cache.covering(want, opt, box.resolution, false);
    return c ? std::optional(distance::GridCover{*c, true}) : std::nullopt;
  };
  distance::PointsRead through = distance::read_points(t, xyz, opt, {}, cover);
  ASSERT_EQ(through.grids.size(), 1u);
  ASSERT_TRUE(distance::same_cells(through.grids[0].box, cached));
  const distance::DistanceField* f = &cache.update(std::move(through.grids[0]), edt, box.resolution, opt);
  const auto got = distance::answer_points(through, std::span<const distance::DistanceField* const>(&f, 1));
  const auto want = distance::answer_points(distance::read_points(t, xyz, opt, {}), edt);
  ASSERT_EQ(got.size(), want.size());
  int near = 0;
  for (size_t p = 0; p < got.size(); ++p) {
    EXPECT_EQ(got[p].distance, want[p].distance) << "point " << p;
    EXPECT_EQ(got[p].gradient, want[p].gradient) << "point " << p;
    EXPECT_EQ(got[p].cell_center, want[p].cell_center) << "point " << p;
    near += got[p].distance < opt.max_distance;
  }
  EXPECT_GT(near, 30);  // not all at the clamp
  // A point outside the cached box: its own grid.
  xyz.insert(xyz.end(), {float(hi[0] + 3), float(hi[1]), float(hi[2])});
  EXPECT_FALSE(distance::same_cells(distance::read_points(t, xyz, opt, {}, cover).grids[0].box, cached));
  // A few cells inside it: their own grid is the cheaper read, unless the cache's grid can be
  // brought up to date without reading it (the change lists).
  distance::CellBox small = cached;
  small.dims = {8, 8, 8};
  for (int a = 0; a < 3; ++a) small.key_lo[a] += 10;
  EXPECT_FALSE(cache.covering(small, opt, box.resolution, false).has_value());
  EXPECT_TRUE(cache.covering(small, opt, box.resolution, true).has_value());
  EXPECT_TRUE(cache.covering(cached, opt, box.resolution, false).has_value());
  // Other options (unknown as occupied): not covered.
  distance::DistanceOptions other = opt;
  other.unknown = UnknownAs::kOccupied;
  EXPECT_FALSE(cache.covering(cached, other, box.resolution, true).has_value());
}

}  // namespace
}  // namespace ort::test
