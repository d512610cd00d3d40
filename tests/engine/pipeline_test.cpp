// `octomap-rt bench` and `octomap-rt build` insert their scans with the engine's two stages
// overlapped (engine/engine_pipeline.h): scan k+1 is shot while scan k is applied. The map
// must be the one sequential insertion gives, and OctoMap's: real scans (../shared/data)
// inserted pipelined and one after the other, on the native grid walk and on Vulkan (with
// its device preparation), with the batched octree stage; and errors in either stage stop
// the run and reach the caller.
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "engine/engine_pipeline.h"
#include "octree/worker_pool.h"
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
  o.shoots_beside_apply = true;  // as bench and build set it when they pipeline
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

// Stage 1 reuses a scan's ShotScan for a later scan (ShotScan::reset keeps the voxel list's
// storage): each scan must come out as from a fresh ShotScan, whatever the one before left
// there (a larger list, a refusal, counts), and its voxels must be those of OctoMap's own
// walk (the cpu back end).
TEST_P(PipelinedInsertion, AReusedShotScanGivesEachScanTheVoxelsOfAFreshOne) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  ASSERT_FALSE(path.empty());
  const ScanSet set = load_scan_graph(path);
  ASSERT_EQ(set.scans.size(), 3u);
  MapEngine engine(engine_options(GetParam()));
  MapEngine reference(engine_options(BackendKind::kCpu));
  const auto sorted = [](VoxelList v) {
    std::sort(v.begin(), v.end(), [](const VoxelUpdate& a, const VoxelUpdate& b) {
      return std::tie(a.z, a.y, a.x, a.state) < std::tie(b.z, b.y, b.x, b.state);
    });
    return v;
  };
  const auto same = [](const VoxelList& a, const VoxelList& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(VoxelUpdate)) == 0;
  };
  ShotScan reused;
  for (size_t i : {0, 1, 2, 1, 0, 2}) {
    const PosedScanInput in = inputs_of(set)(i);
    reused.refusal = ShotRefusal::kTooMuchWork;  // left from an earlier scan
    reused.occupied_voxels = 12345;
    engine.shoot_posed(in.pose, in.origin, in.sensor_points, -1.0, reused);
    ShotScan fresh, walked;
    engine.shoot_posed(in.pose, in.origin, in.sensor_points, -1.0, fresh);
    reference.shoot_posed(in.pose, in.origin, in.sensor_points, -1.0, walked);
    EXPECT_EQ(reused.refusal, ShotRefusal::kNone) << "scan " << i;
    EXPECT_EQ(reused.occupied_voxels, fresh.occupied_voxels) << "scan " << i;
    EXPECT_EQ(reused.free_voxels, fresh.free_voxels) << "scan " << i;
    EXPECT_GT(reused.voxels.size(), 10'000u) << "scan " << i;
    EXPECT_TRUE(same(sorted(reused.voxels), sorted(fresh.voxels))) << "scan " << i;
    EXPECT_TRUE(same(sorted(reused.voxels), sorted(walked.voxels))) << "scan " << i << ": not OctoMap's walk";
  }
}

// Beside a device's stage 1 the octree stage leaves one hardware thread to it, on hosts with
// enough of them; asked-for thread counts and the CPU back ends keep every thread.
TEST(PipelinedInsertion, TheOctreeStageLeavesAThreadToADeviceStageOne) {
  const unsigned hardware = resolve_thread_count(0);
  const unsigned spared = hardware >= kSpareCoreAbove ? hardware - 1 : hardware;
  EXPECT_EQ(MapEngine(engine_options(BackendKind::kVulkan)).octree_threads(), spared);
  EXPECT_EQ(MapEngine(engine_options(BackendKind::kCpuGrid)).octree_threads(), hardware);
  EngineOptions alone = engine_options(BackendKind::kVulkan);
  alone.shoots_beside_apply = false;
  EXPECT_EQ(MapEngine(alone).octree_threads(), hardware);
  EngineOptions asked = engine_options(BackendKind::kVulkan);
  asked.octree.threads = 3;
  EXPECT_EQ(MapEngine(asked).octree_threads(), 3u);
  // The daemon leaves four (its LCM thread, the kernel's network work), at most half of them.
  EngineOptions daemon = engine_options(BackendKind::kVulkan);
  daemon.spare_threads = 4;
  const unsigned daemon_spared = hardware >= kSpareCoreAbove ? hardware - std::min(4u, hardware / 2) : hardware;
  EXPECT_EQ(MapEngine(daemon).octree_threads(), daemon_spared);
}

// bench and build (stage1_helpers_yield): with cpu-grid the octree stage takes half the
// hardware threads, the walk keeps all of them; asked-for counts and the daemon keep theirs.
TEST(PipelinedInsertion, BatchProgramsShareTheCoresBetweenTheWalkAndTheOctreeStage) {
  const unsigned hardware = resolve_thread_count(0);
  EngineOptions batch = engine_options(BackendKind::kCpuGrid);
  batch.stage1_helpers_yield = true;
  EXPECT_EQ(MapEngine(batch).octree_threads(), std::max(1u, hardware / 2));
  EngineOptions asked = batch;
  asked.octree.threads = 2;
  EXPECT_EQ(MapEngine(asked).octree_threads(), 2u);
  EngineOptions sequential = batch;
  sequential.shoots_beside_apply = false;
  EXPECT_EQ(MapEngine(sequential).octree_threads(), hardware);
  EngineOptions daemon = engine_options(BackendKind::kCpuGrid);  // stage1_helpers_yield unset
  EXPECT_EQ(MapEngine(daemon).octree_threads(), hardware);
}

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
