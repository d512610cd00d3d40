// The engine's warm-up (engine/engine_warm_up.h): a synthetic scan shot and applied to a
// scratch tree must leave no trace. Each real scan shot by a warmed-up engine gives the voxel
// list a fresh engine gives (the device grid is clear again, the buffers that grew hold no
// stale rays), and the map built after it is OctoMap's; on the native walk and on Vulkan with
// its device preparation (the daemon's path: sensor-frame floats).
#include <algorithm>
#include <cstdint>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "engine/engine_warm_up.h"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

EngineOptions options(BackendKind kind) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = kind;
  o.backend.compact_into_host_memory = true;  // as the daemon sets it
  o.octree.mode = OctreeUpdateMode::kBatched;
  o.shoots_beside_apply = true;
  return o;
}

// The list as (x, y, z, state) tuples in key order: the back ends emit it in no fixed order.
std::vector<std::tuple<uint16_t, uint16_t, uint16_t, uint16_t>> sorted(const VoxelList& list) {
  std::vector<std::tuple<uint16_t, uint16_t, uint16_t, uint16_t>> v;
  v.reserve(list.size());
  for (const VoxelUpdate& u : list) v.emplace_back(u.x, u.y, u.z, u.state);
  std::sort(v.begin(), v.end());
  return v;
}

void shoot_message_floats(MapEngine& engine, const PosedScan& s, ShotScan& out) {
  std::vector<float> xyz;
  for (const auto& p : s.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  engine.shoot_posed_xyz(s.pose, sensor_origin(s), xyz, engine.options().max_range, out);
}

class EngineWarmUp : public ::testing::TestWithParam<BackendKind> {};

TEST_P(EngineWarmUp, LeavesNoTraceInTheScansOrTheMap) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  ASSERT_FALSE(path.empty());
  const ScanSet set = load_scan_graph(path);
  MapEngine fresh(options(GetParam())), warmed(options(GetParam()));
  const WarmUpReport w = warm_up(warmed, 640 * 480);
  EXPECT_EQ(w.points, 640u * 480u);
  EXPECT_GT(w.voxels, 1000u) << "the warm-up scan was shot and applied";
  EXPECT_FALSE(w.refused);
  auto tree = warmed.make_tree();
  for (size_t i = 0; i < set.scans.size(); ++i) {
    ShotScan a, b;
    shoot_message_floats(fresh, set.scans[i], a);
    shoot_message_floats(warmed, set.scans[i], b);
    ASSERT_GT(a.voxels.size(), 10'000u);
    EXPECT_EQ(b.voxels.size(), a.voxels.size()) << "scan " << i;
    EXPECT_TRUE(sorted(b.voxels) == sorted(a.voxels)) << "scan " << i << ": the warmed engine shot other voxels";
    warmed.apply(b, *tree);
  }
  const auto reference = octomap_reference(set, 0.1, -1.0);
  EXPECT_EQ(compare_structure(*tree, *reference), "");
  const TreeDiff diff = compare_leaves(*tree, *reference);
  EXPECT_TRUE(diff.maps_equal()) << diff.first_difference;
}

TEST_P(EngineWarmUp, NoPointsNoWarmUp) {
  MapEngine engine(options(GetParam()));
  const WarmUpReport w = warm_up(engine, 0);
  EXPECT_EQ(w.points, 0u);
  EXPECT_EQ(w.voxels, 0u);
}

INSTANTIATE_TEST_SUITE_P(Backends, EngineWarmUp, ::testing::Values(BackendKind::kCpuGrid, BackendKind::kVulkan),
                         [](const auto& info) { return info.param == BackendKind::kVulkan ? "vulkan" : "cpu_grid"; });

}  // namespace
}  // namespace ort::test
