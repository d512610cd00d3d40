// Shards (issue 26): N daemons, each keeping the voxels of its own regions. On the real 3DTK
// scans, for 2, 3 and 4 shards: every shard's map is OctoMap's map restricted to its regions,
// and the shards' maps merged are the one-daemon map node for node (its .bt byte for byte),
// both from the engine's lists and through whole daemons over memq://.
#include <limits>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/pipeline/shard_filter.h"
#include "map_client/shard_merge.h"
#include "octomap_rt/server_status_t.hpp"
#include "octree/region.h"
#include "protocol/channels.h"
#include "protocol/shards/shard_wire.h"
#include "scene/scan_set.h"
#include "server/scan_fixtures.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

using protocol::RegionBox;
using protocol::ShardRule;
using protocol::ShardSet;

ShardSet hash_set(uint32_t index, uint32_t count, uint32_t depth) {
  ShardSet s;
  s.index = index, s.count = count, s.rule = ShardRule::kHash, s.region_depth = depth;
  return s;
}

// OctoMap 1.9.7's deleteNodeChild frees one node, not its children or its child array: a
// node's subtree is emptied leaf by leaf, then its empty child array freed (expandNode and
// pruneNode), so the node is a plain leaf that deleteNodeChild may free.
void make_leaf(octomap::OcTree& tree, octomap::OcTreeNode* node) {
  for (unsigned j = 0; j < 8; ++j) {
    if (!tree.nodeChildExists(node, j)) continue;
    octomap::OcTreeNode* child = tree.getNodeChild(node, j);
    if (tree.nodeHasChildren(child)) make_leaf(tree, child);
    tree.deleteNodeChild(node, j);
  }
  tree.expandNode(node);
  tree.pruneNode(node);
}

// Deletes every region of `node`'s subtree that other shards own (coarse leaves over several
// shards' regions split down to the region depth first); false when nothing is left, the node
// then a plain leaf: OctoMap's map restricted to the filter's shard.
bool keep_owned_below(octomap::OcTree& tree, const daemon::ShardFilter& f, octomap::OcTreeNode* node,
                      const octomap::OcTreeKey& min_key, unsigned depth) {
  if (depth == f.set().region_depth) return f.owns(min_key);
  if (!tree.nodeHasChildren(node)) tree.expandNode(node);
  const uint16_t half = static_cast<uint16_t>(1u << (15 - depth));
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    octomap::OcTreeKey k = min_key;
    for (unsigned a = 0; a < 3; ++a)
      if (i & (1u << a)) k[a] = static_cast<uint16_t>(k[a] + half);
    octomap::OcTreeNode* child = tree.getNodeChild(node, i);
    if (keep_owned_below(tree, f, child, k, depth + 1)) continue;
    if (tree.nodeHasChildren(child)) make_leaf(tree, child);
    tree.deleteNodeChild(node, i);
  }
  if (tree.nodeHasChildren(node)) return true;
  tree.expandNode(node);
  tree.pruneNode(node);
  return false;
}

std::unique_ptr<octomap::OcTree> restricted(const octomap::OcTree& full, const ShardSet& set) {
  auto t = std::make_unique<octomap::OcTree>(full);
  if (t->getRoot() && !keep_owned_below(*t, daemon::ShardFilter(set), t->getRoot(), octomap::OcTreeKey(0, 0, 0), 0))
    t->clear();
  return t;
}

std::string bt_bytes(octomap::OcTree tree) {
  std::ostringstream out;
  tree.writeBinary(out);
  return out.str();
}

void expect_same_map(const octomap::OcTree& a, const octomap::OcTree& b, const std::string& what) {
  const TreeDiff d = compare_leaves(a, b);
  EXPECT_TRUE(d.maps_equal()) << what << ": " << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
}

// The merged map of `shards` against the one-daemon map `whole`: node for node, .bt bytes.
void expect_merge_is_whole(const std::vector<std::unique_ptr<octomap::OcTree>>& shards, unsigned depth,
                           const octomap::OcTree& whole, const std::string& what) {
  std::vector<const octomap::OcTree*> views;
  for (const auto& s : shards) views.push_back(s.get());
  const auto merged = client::merge_shard_trees(views, depth);
  expect_same_map(*merged, whole, what + ", merged");
  EXPECT_EQ(compare_structure(*merged, whole), "") << what;
  EXPECT_EQ(merged->size(), whole.size()) << what;
  EXPECT_TRUE(bt_bytes(*merged) == bt_bytes(whole)) << what << ": the merged .bt differs";
}

TEST(ShardRule, RegionCoordinatesAreTheRegionAbstractions) {
  for (unsigned depth : {1u, 7u, 10u, 16u}) {
    const RegionGrid grid = region_grid(depth);
    for (uint32_t k = 0; k < 65536; k += 4093) {
      const octomap::OcTreeKey key(static_cast<uint16_t>(k), static_cast<uint16_t>(65535 - k),
                                   static_cast<uint16_t>(k * 7));
      const RegionId id = region_of(grid, key);
      const protocol::RegionCoords r = protocol::region_coords(depth, key[0], key[1], key[2]);
      EXPECT_EQ(r.x, id & 0xffff);
      EXPECT_EQ(r.y, id >> 16 & 0xffff);
      EXPECT_EQ(r.z, id >> 32 & 0xffff);
    }
  }
}

TEST(ShardRule, HashSpreadsRegionsOverEveryShard) {
  for (uint32_t n : {2u, 3u, 4u, 7u}) {
    std::vector<int> owned(n);
    for (uint32_t x = 0; x < 32; ++x)
      for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t z = 0; z < 8; ++z) owned[protocol::shard_of(hash_set(0, n, 10), {512 + x, 512 + y, 512 + z})]++;
    for (uint32_t i = 0; i < n; ++i)
      EXPECT_NEAR(owned[i], 8192.0 / n, 0.1 * 8192.0 / n) << "shard " << i << " of " << n;
  }
}

TEST(ShardRule, BoxesMustTileTheKeySpace) {
  const double inf = std::numeric_limits<double>::infinity();
  const double all_min[3] = {-inf, -inf, -inf}, all_max[3] = {inf, inf, inf};
  ShardSet s;
  s.rule = ShardRule::kBoxes, s.count = 2, s.region_depth = 10;
  const double west_max[3] = {0, inf, inf}, east_min[3] = {0, -inf, -inf};
  s.boxes = {protocol::region_box_of(all_min, west_max, 0.1, 10), protocol::region_box_of(east_min, all_max, 0.1, 10)};
  EXPECT_EQ(protocol::check_shard_set(s), "");
  EXPECT_EQ(s.boxes[0].max[0], 512u);  // 0 m is region 512's min corner at 0.1 m, depth 10
  EXPECT_EQ(protocol::shard_of(s, {511, 3, 900}), 0u);
  EXPECT_EQ(protocol::shard_of(s, {512, 3, 900}), 1u);
  const double east_of_1m[3] = {1, -inf, -inf};  // a gap from 0 to 1 m
  s.boxes[1] = protocol::region_box_of(east_of_1m, all_max, 0.1, 10);
  EXPECT_NE(protocol::check_shard_set(s).find("gap: region (512, 0, 0)"), std::string::npos)
      << protocol::check_shard_set(s);
  const double east_of_minus_7m[3] = {-7, -inf, -inf};  // an overlap: region 511 (-6.4 .. 0 m)
  s.boxes[1] = protocol::region_box_of(east_of_minus_7m, all_max, 0.1, 10);
  EXPECT_NE(protocol::check_shard_set(s).find("boxes 0 and 1 overlap"), std::string::npos)
      << protocol::check_shard_set(s);
  s.boxes.pop_back();
  EXPECT_NE(protocol::check_shard_set(s).find("1 boxes for 2 shards"), std::string::npos);
  uint32_t i = 0, n = 0;
  for (const char* bad : {"", "1", "2/2", "-1/2", "0/0", "0/65", "a/b", "0/2x"})
    EXPECT_NE(protocol::parse_shard_index(bad, i, n), "") << bad;
  EXPECT_EQ(protocol::parse_shard_index("2/3", i, n), "");
  EXPECT_EQ(i, 2u);
  EXPECT_EQ(n, 3u);
}

// The announcement's fields, read back with every field range-checked and a named fault.
TEST(ShardRule, AnnouncedFieldsAreRangeCheckedWithNamedFaults) {
  octomap_rt::server_status_t m{};
  ShardSet boxes;
  boxes.index = 1, boxes.count = 2, boxes.rule = ShardRule::kBoxes, boxes.region_depth = 3;
  boxes.boxes = {RegionBox{{0, 0, 0}, {4, 8, 8}}, RegionBox{{4, 0, 0}, {8, 8, 8}}};
  protocol::put_shard_set(boxes, m);
  ShardSet back;
  ASSERT_EQ(protocol::read_shard_set(m, back), protocol::ShardFieldFault::kNone);
  EXPECT_TRUE(protocol::same_shard_set(back, boxes));
  EXPECT_EQ(back.index, 1u);
  auto fault = [&](auto change) {
    octomap_rt::server_status_t c = m;
    change(c);
    ShardSet ignored;
    return protocol::read_shard_set(c, ignored);
  };
  using F = protocol::ShardFieldFault;
  EXPECT_EQ(fault([](auto& c) { c.shard_rule = 3; }), F::kUnknownRule);
  EXPECT_EQ(fault([](auto& c) { c.shard_rule = -1; }), F::kUnknownRule);
  EXPECT_EQ(fault([](auto& c) { c.shard_region_depth = 0; }), F::kBadDepth);
  EXPECT_EQ(fault([](auto& c) { c.shard_region_depth = 17; }), F::kBadDepth);
  EXPECT_EQ(fault([](auto& c) { c.shard_count = 0; }), F::kBadCount);
  EXPECT_EQ(fault([](auto& c) { c.shard_count = 65; }), F::kBadCount);
  EXPECT_EQ(fault([](auto& c) { c.shard_index = 2; }), F::kBadIndex);
  EXPECT_EQ(fault([](auto& c) { c.shard_index = -1; }), F::kBadIndex);
  EXPECT_EQ(fault([](auto& c) { c.shard_box.pop_back(), c.num_shard_box_values--; }), F::kBadBoxValues);
  EXPECT_EQ(fault([](auto& c) { c.num_shard_box_values = 1 << 30; }), F::kBadBoxValues);
  EXPECT_EQ(fault([](auto& c) { c.shard_box[3] = 5; }), F::kBadBoxes);   // box 0 overlaps box 1
  EXPECT_EQ(fault([](auto& c) { c.shard_box[9] = 9; }), F::kBadBoxes);   // past the key space
  EXPECT_EQ(fault([](auto& c) { c.shard_box[0] = -1; }), F::kBadBoxes);  // negative
  EXPECT_EQ(fault([](auto& c) { c.shard_rule = 0; }), F::kBadCount);     // the whole map in two
  EXPECT_STREQ(protocol::to_string(F::kBadIndex), "shard index not below the count");
}

// The engine's voxel lists of the real scans, cut per shard: every shard equals OctoMap
// restricted to its regions; the merge equals the one-daemon map.
TEST(Shards, RealScansShardByShardEqualOctomapAndMergeToTheWholeMap) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  const auto cfg = test_config(0.2, false);
  MapEngine engine(cfg.engine);
  std::vector<ShotScan> shots(set.scans.size());
  auto whole = engine.make_tree();
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const octomap::Pointcloud pts = world_points(set.scans[k]);
    std::vector<octomap::point3d> points(pts.begin(), pts.end());
    engine.shoot(sensor_origin(set.scans[k]), points, cfg.engine.max_range, shots[k]);
    ShotScan copy = shots[k];
    engine.apply(copy, *whole);
  }
  const auto reference = octomap_reference(set, cfg.engine.resolution, cfg.engine.max_range);
  expect_same_map(*whole, *reference, "one daemon");
  for (const uint32_t depth : {10u, 12u}) {
    for (uint32_t n = 2; n <= 4; ++n) {
      std::vector<std::unique_ptr<octomap::OcTree>> shards;
      for (uint32_t i = 0; i < n; ++i) {
        const ShardSet s = hash_set(i, n, depth);
        shards.push_back(engine.make_tree());
        for (const ShotScan& shot : shots) {
          ShotScan mine = shot;
          daemon::ShardFilter(s).keep_owned(mine);
          engine.apply(mine, *shards.back());
        }
        const std::string what =
            "shard " + std::to_string(i) + " of " + std::to_string(n) + ", depth " + std::to_string(depth);
        expect_same_map(*shards.back(), *restricted(*reference, s), what);
        EXPECT_GT(shards.back()->size(), 100u) << what;  // every shard maps some of it
      }
      expect_merge_is_whole(shards, depth, *whole, std::to_string(n) + " shards, depth " + std::to_string(depth));
    }
  }
}

// The engine's ray clip, as the daemon sets it (a shard leaves out the rays whose walk meets none
// of its regions): each shard's map is still OctoMap's map restricted to its regions, the box
// shard away from the sensors left rays out, and the hashed set some. 4 hashed shards (regions at
// depth 10: 12.8 m) and 2 boxes cut at x = 5 m (the sensors stand near x = 0; y is up in 3DTK).
TEST(Shards, ClippedRaysLeaveEveryShardOctomapsMap) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  const auto cfg = test_config(0.2, false);
  const auto reference = octomap_reference(set, cfg.engine.resolution, cfg.engine.max_range);
  std::vector<ShardSet> sets;
  for (uint32_t i = 0; i < 4; ++i) sets.push_back(hash_set(i, 4, 10));
  const double inf = std::numeric_limits<double>::infinity();
  const double lo[3] = {-inf, -inf, -inf}, hi[3] = {inf, inf, inf}, cut_max[3] = {5.0, inf, inf},
               cut_min[3] = {5.0, -inf, -inf};
  uint64_t hashed_clipped = 0, hashed_rays = 0;
  for (uint32_t i = 0; i < 2; ++i) {
    ShardSet s;
    s.index = i, s.count = 2, s.rule = ShardRule::kBoxes, s.region_depth = 11;
    s.boxes = {protocol::region_box_of(lo, cut_max, 0.2, 11), protocol::region_box_of(cut_min, hi, 0.2, 11)};
    sets.push_back(s);
  }
  for (const ShardSet& s : sets) {
    const daemon::ShardFilter filter(s);
    MapEngine engine(cfg.engine);
    engine.set_ray_clip([&](const KeyBox& box) { return filter.may_hold(box); });
    auto tree = engine.make_tree();
    uint64_t clipped = 0, rays = 0;
    for (const PosedScan& scan : set.scans) {
      const octomap::Pointcloud pts = world_points(scan);
      std::vector<octomap::point3d> points(pts.begin(), pts.end());
      ShotScan shot;
      engine.shoot(sensor_origin(scan), points, cfg.engine.max_range, shot);
      clipped += shot.clipped_rays, rays += points.size();
      filter.keep_owned(shot);
      engine.apply(shot, *tree);
    }
    const std::string what = protocol::describe(s);
    expect_same_map(*tree, *restricted(*reference, s), what);
    if (s.rule == ShardRule::kBoxes)  // the box holding the sensors keeps every ray, the other not
      EXPECT_EQ(clipped > rays / 20, s.index == 1) << what << ": " << clipped << " of " << rays << " rays left out";
    else
      hashed_clipped += clipped, hashed_rays += rays;
  }
  EXPECT_GT(hashed_clipped, hashed_rays / 50) << hashed_clipped << " of " << hashed_rays << " rays left out";
}

std::string scan_channel(const std::string& robot) {
  std::string c = protocol::kScanChannelPrefix;
  for (char ch : robot) c += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return c;
}

// Whole daemons, one producer, the same order everywhere: 2 boxes and 3 hashed shards.
TEST(Shards, DaemonsOverMemqMergeToTheOneDaemonMap) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  const double inf = std::numeric_limits<double>::infinity();
  const double lo[3] = {-inf, -inf, -inf}, hi[3] = {inf, inf, inf}, cut_max[3] = {inf, 2.0, inf},
               cut_min[3] = {-inf, 2.0, -inf};
  std::vector<ShardSet> sets;
  for (uint32_t i = 0; i < 2; ++i) {
    ShardSet s;
    s.index = i, s.count = 2, s.rule = ShardRule::kBoxes, s.region_depth = 11;
    s.boxes = {protocol::region_box_of(lo, cut_max, 0.2, 11), protocol::region_box_of(cut_min, hi, 0.2, 11)};
    sets.push_back(s);
  }
  for (uint32_t i = 0; i < 3; ++i) sets.push_back(hash_set(i, 3, 10));
  sets.push_back(ShardSet{});  // the one daemon
  std::vector<std::unique_ptr<lcm::LCM>> buses;
  std::vector<std::unique_ptr<daemon::MappingServer>> servers;
  std::ostringstream log;
  for (const ShardSet& s : sets) {
    auto cfg = test_config(0.2, true);
    cfg.shard = s;
    buses.push_back(std::make_unique<lcm::LCM>("memq://"));
    servers.push_back(std::make_unique<daemon::MappingServer>(cfg, *buses.back(), log));
    servers.back()->start();
  }
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "husky1", static_cast<int64_t>(k));
    for (auto& bus : buses) bus->publish(scan_channel("husky1"), &msg);
  }
  std::vector<std::unique_ptr<octomap::OcTree>> maps;
  for (size_t i = 0; i < servers.size(); ++i) {  // each announces the whole set it belongs to
    ShardSet heard;
    EXPECT_EQ(protocol::read_shard_set(servers[i]->status(), heard), protocol::ShardFieldFault::kNone);
    EXPECT_TRUE(protocol::same_shard_set(heard, sets[i])) << protocol::describe(heard);
    EXPECT_EQ(heard.index, sets[i].index);
  }
  for (auto& server : servers) {
    ASSERT_TRUE(wait_until_done(*server, static_cast<int64_t>(set.scans.size())));
    server->stop();
    expect_counts_balance(server->producer_stats());
    EXPECT_EQ(server->applied_order().size(), set.scans.size());  // every shard accounts for every scan
    maps.push_back(server->with_map([](const octomap::OcTree& m) { return std::make_unique<octomap::OcTree>(m); }));
  }
  const auto reference = octomap_reference(set, 0.2, test_config(0.2, true).engine.max_range);
  expect_same_map(*maps.back(), *reference, "one daemon");
  for (size_t i = 0; i < sets.size() - 1; ++i)
    expect_same_map(*maps[i], *restricted(*reference, sets[i]), "daemon shard " + std::to_string(i));
  std::vector<std::unique_ptr<octomap::OcTree>> boxes, hashed;
  boxes.push_back(std::move(maps[0])), boxes.push_back(std::move(maps[1]));
  for (int i = 2; i < 5; ++i) hashed.push_back(std::move(maps[i]));
  expect_merge_is_whole(boxes, 11, *maps.back(), "2 boxes");
  expect_merge_is_whole(hashed, 10, *maps.back(), "3 hashed shards");
}

// Three producers, each shard hearing them in an order of its own (the buses are fed rotated):
// every shard's map is OctoMap's map of the scans in that shard's applied order, restricted to
// its regions (the consistency PROTOCOL.md states for a shard set).
TEST(Shards, EachShardIsOctomapOnItsOwnOrderWithThreeProducers) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  ScanSet set = load_scan_graph(path);
  for (PosedScan& s : set.scans) {  // every 3rd point: nine scans in seconds
    octomap::Pointcloud kept;
    for (size_t i = 0; i < s.points.size(); i += 3) kept.push_back(s.points[i]);
    s.points = kept;
  }
  const std::vector<std::string> robots = {"r0", "r1", "r2"};
  std::vector<std::unique_ptr<lcm::LCM>> buses;
  std::vector<std::unique_ptr<daemon::MappingServer>> servers;
  std::ostringstream log;
  for (uint32_t i = 0; i < 3; ++i) {
    auto cfg = test_config(0.2, true);
    cfg.shard = hash_set(i, 3, 10);
    buses.push_back(std::make_unique<lcm::LCM>("memq://"));
    servers.push_back(std::make_unique<daemon::MappingServer>(cfg, *buses.back(), log));
    servers.back()->start();
  }
  for (size_t k = 0; k < set.scans.size(); ++k)
    for (size_t b = 0; b < buses.size(); ++b)
      for (size_t r = 0; r < robots.size(); ++r) {  // bus b hears robot (b + r) % 3 first
        const std::string& robot = robots[(b + r) % robots.size()];
        const auto msg = scan_message(set.scans[k], robot, static_cast<int64_t>(k));
        buses[b]->publish(scan_channel(robot), &msg);
      }
  const int64_t all = static_cast<int64_t>(set.scans.size() * robots.size());
  std::vector<std::vector<std::string>> orders;
  for (uint32_t i = 0; i < servers.size(); ++i) {
    ASSERT_TRUE(wait_until_done(*servers[i], all));
    servers[i]->stop();
    const auto order = servers[i]->applied_order();
    ASSERT_EQ(order.size(), size_t(all));
    ScanSet in_order;
    std::vector<std::string> names;
    for (const auto& e : order) {
      in_order.scans.push_back(set.scans.at(size_t(e.seq)));
      names.push_back(e.robot_id + "/" + std::to_string(e.seq));
    }
    orders.push_back(names);
    const auto map =
        servers[i]->with_map([](const octomap::OcTree& m) { return std::make_unique<octomap::OcTree>(m); });
    const auto reference = octomap_reference(in_order, 0.2, test_config(0.2, true).engine.max_range);
    expect_same_map(*map, *restricted(*reference, hash_set(i, 3, 10)), "shard " + std::to_string(i) + " of 3");
  }
  EXPECT_NE(orders[0], orders[1]);  // the shards' orders differ: each is checked against its own
}

}  // namespace
}  // namespace ort::test
