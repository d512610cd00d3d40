// `octomap-rt bench` and `octomap-rt build` insert their scans with the engine's two stages
// overlapped (engine/engine_pipeline.h): scan k+1 is shot while scan k is applied. The map
// must be the one sequential insertion gives, and OctoMap's: real scans (../shared/data)
// inserted pipelined and one after the other, on the native grid walk and on Vulkan (with
// its device preparation), with the batched octree stage; and errors in either stage stop
// the run and reach the caller.
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "engine/engine_pipeline.h"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

// The data set's scans twice over: replayed scans saturate voxels and prune free space, and
// six scans pass through both hand-off slots several times.
ScanSet replayed(const ScanSet& set) {
  ScanSet twice = set;
  twice.scans.insert(twice.scans.end(), set.scans.begin(), set.scans.end());
  return twice;
}

ScanInputSource inputs_of(const ScanSet& set) {
  return [&set](size_t i) {
    const PosedScan& s = set.scans[i];
    return PosedScanInput{s.pose, sensor_origin(s), {s.points.size() ? &s.points[0] : nullptr, s.points.size()}};
  };
}

EngineOptions engine_options(BackendKind kind) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = kind;
  o.octree.mode = OctreeUpdateMode::kBatched;
  return o;
}

class PipelinedInsertion : public ::testing::TestWithParam<BackendKind> {};

TEST_P(PipelinedInsertion, GivesTheSequentialTreeAndOctoMapsOnRealScans) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  ASSERT_FALSE(path.empty());
  const ScanSet set = replayed(load_scan_graph(path));
  const auto reference = octomap_reference(set, 0.1, -1.0);

  MapEngine engine(engine_options(GetParam()));
  auto sequential = engine.make_tree();
  insert_scans(engine, set.scans.size(), inputs_of(set), *sequential, {}, /*pipelined=*/false);
  auto pipelined = engine.make_tree();
  std::vector<size_t> order;
  uint64_t voxels = 0;
  insert_scans(engine, set.scans.size(), inputs_of(set), *pipelined, [&](size_t i, const ShotScan& shot) {
    order.push_back(i);
    voxels += shot.voxels.size();
    EXPECT_EQ(shot.refusal, ShotRefusal::kNone) << "scan " << i;
    EXPECT_GT(shot.shoot.times.octree_ms, 0.0) << "scan " << i << " reached the sink before it was applied";
  });

  ASSERT_EQ(order.size(), set.scans.size());
  for (size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], i) << "scans applied out of order";
  EXPECT_GT(voxels, 100'000u);
  EXPECT_EQ(compare_structure(*pipelined, *sequential), "");
  EXPECT_EQ(compare_structure(*pipelined, *reference), "");
  const TreeDiff diff = compare_leaves(*pipelined, *reference);
  EXPECT_TRUE(diff.maps_equal()) << diff.first_difference;
}

INSTANTIATE_TEST_SUITE_P(Backends, PipelinedInsertion, ::testing::Values(BackendKind::kCpuGrid, BackendKind::kVulkan),
                         [](const auto& info) { return info.param == BackendKind::kVulkan ? "vulkan" : "cpu_grid"; });

// A small scene: a wall of points in front of the sensor.
ScanSet small_scans(size_t n) {
  ScanSet set;
  for (size_t k = 0; k < n; ++k) {
    PosedScan s;
    s.pose = octomap::pose6d(0.1 * k, 0, 0, 0, 0, 0);
    for (int y = -10; y <= 10; ++y)
      for (int z = -5; z <= 5; ++z) s.points.push_back(3.0f, 0.1f * y, 0.1f * z);
    set.scans.push_back(std::move(s));
  }
  return set;
}

TEST(PipelinedInsertion, AnErrorInStageOneStopsTheRunAndReachesTheCaller) {
  const ScanSet set = small_scans(6);
  MapEngine engine(engine_options(BackendKind::kCpuGrid));
  auto tree = engine.make_tree();
  const ScanInputSource source = [&](size_t i) {
    if (i == 3) throw std::runtime_error("scan 3 cannot be read");
    return inputs_of(set)(i);
  };
  std::vector<size_t> applied;
  try {
    insert_scans(engine, set.scans.size(), source, *tree, [&](size_t i, const ShotScan&) { applied.push_back(i); });
    FAIL() << "the source's error was swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "scan 3 cannot be read");
  }
  EXPECT_LE(applied.size(), 3u);
  for (size_t i = 0; i < applied.size(); ++i) EXPECT_EQ(applied[i], i);
}

TEST(PipelinedInsertion, AnErrorInStageTwoStopsStageOneAndReachesTheCaller) {
  const ScanSet set = small_scans(8);
  MapEngine engine(engine_options(BackendKind::kCpuGrid));
  auto tree = engine.make_tree();
  size_t shot = 0;
  const ScanInputSource source = [&](size_t i) {
    ++shot;
    return inputs_of(set)(i);
  };
  try {
    insert_scans(engine, set.scans.size(), source, *tree, [](size_t i, const ShotScan&) {
      if (i == 2) throw std::runtime_error("the map's store failed on scan 2");
    });
    FAIL() << "the sink's error was swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "the map's store failed on scan 2");
  }
  EXPECT_LE(shot, 4u) << "stage 1 ran on past the hand-off after stage 2 failed";
}

}  // namespace
}  // namespace ort::test
