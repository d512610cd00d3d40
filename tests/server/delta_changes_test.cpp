// Map deltas from the octree stage's change log, on real scans (../shared/data: 3dtk,
// scan_dat, a few fr079-real scans at 0.1 m, each replayed so that voxels saturate and free
// space gets pruned), scan by scan and over multi-scan sets:
// - the log of the daemon's octree stage (batched, several threads) = the true change set,
//   found by OctoMap's search() of every key before and after the scan; the map stays
//   OctoMap's own (updateNode loop), node for node;
// - the class-mode and exact-mode change sets the publisher sends (daemon/delta_changes.h) =
//   the true class changes / the true value changes;
// - against the look-up path the daemon used before (one search per voxel after the update,
//   the class before estimated from the value after and the scan's update): the same class
//   changes; in exact mode it also sent the keys at the clamping bound, unchanged;
// - a set spanning many scans, applied to a mirror of the classes at its start, gives the
//   classes at its end.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "daemon/map/delta_changes.h"
#include "engine/map_engine.h"
#include "octomap_rt/map_delta_t.hpp"
#include "protocol/delta_codec.h"
#include "scene/scan_set.h"
#include "scene/scene_presets.h"
#include "support/leaf_change_truth.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::daemon {
namespace {

using Delta = octomap_rt::map_delta_t;
using protocol::VoxelChange;

constexpr int8_t kUnknown = 0;

int8_t class_of(const test::KeyValue& v, float thr) {
  if (!v.known) return kUnknown;
  return v.value >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
}

uint64_t packed(uint64_t morton) {
  uint16_t x, y, z;
  morton_decode(morton, x, y, z);
  return protocol::pack_key(octomap::OcTreeKey(x, y, z));
}

// The look-up path the daemon used before (DeltaPublisher::changes_in up to 2026-11-29).
int old_class_before(const octomap::OcTree& t, float after, float u) {
  const float lo = t.getClampingThresMinLog(), hi = t.getClampingThresMaxLog(), thr = t.getOccupancyThresLog();
  const bool clamped = (u > 0 && after >= hi) || (u < 0 && after <= lo);
  if (clamped) {
    const float bound = u > 0 ? hi : lo;
    if (std::fabs(bound - thr) <= std::fabs(u) + 1e-4f) return -1;
    return bound >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
  }
  const float before = after - u;
  if (before == 0.0f) return 0;
  if (std::fabs(before) < 1e-4f || std::fabs(before - thr) < 1e-4f) return -1;
  return before >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
}
std::vector<VoxelChange> old_lookup(const VoxelList& voxels, const octomap::OcTree& tree, bool exact) {
  const float hit = tree.getProbHitLog(), miss = tree.getProbMissLog(), thr = tree.getOccupancyThresLog();
  std::vector<VoxelChange> out;
  for (const VoxelUpdate& v : voxels) {
    const octomap::OcTreeNode* node = tree.search(v.key());
    if (!node) continue;
    const float after = node->getLogOdds();
    const int8_t now = after >= thr ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
    if (exact)
      out.push_back({protocol::pack_key(v.key()), after});
    else if (old_class_before(tree, after, v.occupied() ? hit : miss) != now)
      out.push_back({protocol::pack_key(v.key()), static_cast<float>(now)});
  }
  keep_newest_per_key(out);
  return out;
}

std::vector<VoxelChange> sent(const std::vector<const LeafChanges*>& logs, bool exact, float thr) {
  std::vector<VoxelChange> set;
  for (const LeafChanges* log : logs) append_delta_changes(*log, exact, thr, set);
  keep_newest_per_key(set);
  return set;
}

struct Totals {
  long scans = 0, changes = 0, class_changes = 0, old_extra_class = 0, old_extra_exact = 0;
};

// One scan: the sets the publisher would send for it against the truth and the old path.
void check_scan(const VoxelList& voxels, const test::KeyValues& before, const octomap::OcTree& tree,
                const LeafChanges& log, const std::string& where, Totals& t) {
  const float thr = tree.getOccupancyThresLog();
  const test::KeyValues after = test::values_of(tree, voxels);
  const test::KeyChanges truth = test::true_changes(before, after);
  ASSERT_EQ(test::collapse(log), truth) << where;

  std::vector<VoxelChange> class_truth, exact_truth;
  for (const auto& [code, c] : truth) {
    exact_truth.push_back({packed(code), c.after});
    const int8_t now = class_of(after.at(code), thr);
    if (class_of(before.at(code), thr) != now) class_truth.push_back({packed(code), static_cast<float>(now)});
  }
  auto by_key = [](const VoxelChange& a, const VoxelChange& b) { return a.key < b.key; };
  std::sort(class_truth.begin(), class_truth.end(), by_key);
  std::sort(exact_truth.begin(), exact_truth.end(), by_key);
  const std::vector<VoxelChange> class_set = sent({&log}, false, thr), exact_set = sent({&log}, true, thr);
  ASSERT_EQ(class_set, class_truth) << where << ": class mode";
  ASSERT_EQ(exact_set, exact_truth) << where << ": exact mode";
  t.scans++;
  t.changes += static_cast<long>(exact_set.size());
  t.class_changes += static_cast<long>(class_set.size());

  // The old path: a superset with the same values; what it sent besides changed nothing.
  for (const bool exact : {false, true}) {
    const std::vector<VoxelChange> old = old_lookup(voxels, tree, exact);
    const std::vector<VoxelChange>& now = exact ? exact_set : class_set;
    std::map<uint64_t, float> old_by_key;
    for (const VoxelChange& c : old) old_by_key[c.key] = c.value;
    for (const VoxelChange& c : now) {
      auto it = old_by_key.find(c.key);
      ASSERT_TRUE(it != old_by_key.end()) << where << ": the old path missed a change (exact " << exact << ")";
      ASSERT_EQ(it->second, c.value) << where << " (exact " << exact << ")";
      old_by_key.erase(it);
    }
    for (const auto& [key, value] : old_by_key) {
      const octomap::OcTreeKey k = protocol::unpack_key(key);
      const uint64_t code = morton_code(k[0], k[1], k[2]);
      if (exact)
        ASSERT_EQ(before.at(code).value, value) << where << ": an old extra that was a change";
      else
        ASSERT_EQ(class_of(before.at(code), thr), static_cast<int8_t>(value)) << where << ": an old extra class change";
    }
    (exact ? t.old_extra_exact : t.old_extra_class) += static_cast<long>(old_by_key.size());
  }
}

std::vector<PosedScan> scans_of(const std::string& name) {
  if (name == "fr079-real") {
    PresetOptions o;
    o.scan_scale = 0.05;  // 3 of the 66 scans
    o.point_scale = 0.25;
    o.data_dir = test::data_dir();
    return make_preset("fr079-real", o).scans;
  }
  const std::string path = test::data_file(name);
  if (path.empty()) return {};
  return load_scan_graph(path).scans;
}

void check_data_set(const std::string& name) {
  const std::vector<PosedScan> scans = scans_of(name);
  ASSERT_FALSE(scans.empty()) << name;
  EngineOptions opts;
  opts.resolution = 0.1;
  opts.backend.kind = BackendKind::kCpu;  // OctoMap's own ray walk
  opts.octree.mode = OctreeUpdateMode::kBatched;
  opts.octree.threads = 4;
  MapEngine engine(opts);
  std::unique_ptr<octomap::OcTree> tree = engine.make_tree(), reference = engine.make_tree();
  std::vector<VoxelList> lists;
  for (const PosedScan& s : scans) {
    const octomap::Pointcloud world = world_points(s);
    ShotScan shot;
    engine.shoot(sensor_origin(s), std::span<const octomap::point3d>(&world[0], world.size()), opts.max_range, shot);
    lists.push_back(std::move(shot.voxels));
  }
  Totals t;
  // Replays: saturation, pruning, keys at the clamping bound (a lone scan needs 5 misses).
  const int passes = lists.size() < 3 ? 6 : 3;
  for (int pass = 0; pass < passes; ++pass) {
    // The whole pass as one change set too: a mirror of the classes at its start, with the
    // set applied, has the classes at its end.
    VoxelList all;
    for (const VoxelList& l : lists) all.insert(all.end(), l.begin(), l.end());
    const test::KeyValues pass_before = test::values_of(*tree, all);
    std::vector<LeafChanges> logs(lists.size());
    for (size_t s = 0; s < lists.size(); ++s) {
      const std::string where = name + ", pass " + std::to_string(pass) + ", scan " + std::to_string(s);
      const test::KeyValues before = test::values_of(*tree, lists[s]);
      ShotScan shot;
      shot.voxels = lists[s];
      engine.apply(shot, *tree, &logs[s]);
      apply_updates_sequential(*reference, lists[s]);
      ASSERT_EQ(test::compare_structure(*reference, *tree), "") << where;
      check_scan(lists[s], before, *tree, logs[s], where, t);
    }
    const float thr = tree->getOccupancyThresLog();
    std::vector<const LeafChanges*> ptrs;
    for (const LeafChanges& l : logs) ptrs.push_back(&l);
    std::map<uint64_t, int8_t> mirror;
    for (const auto& [code, v] : pass_before) mirror[packed(code)] = class_of(v, thr);
    for (const VoxelChange& c : sent(ptrs, false, thr)) mirror[c.key] = static_cast<int8_t>(c.value);
    for (const auto& [code, v] : test::values_of(*tree, all))
      ASSERT_EQ(mirror.at(packed(code)), class_of(v, thr)) << name << ", pass " << pass << ": the set's mirror";
  }
  std::printf(
      "%s: %ld scans, %ld leaf changes, %ld class changes; the old look-up path sent %ld / %ld no-ops "
      "besides (class / exact mode)\n",
      name.c_str(), t.scans, t.changes, t.class_changes, t.old_extra_class, t.old_extra_exact);
  EXPECT_GT(t.class_changes, 0);
  // On these data the old estimate was never ambiguous: in class mode it sent exactly this.
  EXPECT_EQ(t.old_extra_class, 0);
  EXPECT_GT(t.old_extra_exact, 0) << "no clamped keys: the replays did not saturate anything";
}

TEST(DeltaChangesRealData, ThreeDtk) { check_data_set("3dtk_dat/3dtk_3scans.graph"); }
TEST(DeltaChangesRealData, ScanDat) { check_data_set("octomap_share/scan_dat.graph"); }
TEST(DeltaChangesRealData, Fr079Real) { check_data_set("fr079-real"); }

}  // namespace
}  // namespace ort::daemon
