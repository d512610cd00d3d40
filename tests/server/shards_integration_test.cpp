// A shard set with real processes in a network namespace (docs/PROTOCOL.md, "Shards"): three
// octomap-rt-server --shard i/3 in one namespace hear a robot's real scans (3DTK) over udpm.
// The CLI finds them by their statuses and merges their snapshots into one .bt that is OctoMap's
// map of those scans; points and rays routed by region get OctoMap's answers, distances (points
// with the gradient, a box, a path through the CLI) the distances on OctoMap's map, a band's grid
// OctoMap's projected map, a box's nodes (region lists) OctoMap's nodes of the box, a query
// right after a scan that waits for it on every shard (read-your-writes) OctoMap's map after it, a clear-box goes to the shard owning its box; with one shard
// stopped, the map and the answers say they are partial and which shard is missing.
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>

#include "core/clock.h"
#include "distance/distance_queries.h"
#include "distance/squared_edt.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/shards/shard_set.h"
#include "query/key_box.h"
#include "query/point_query.h"
#include "query/projected_grid.h"
#include "query/ray_query.h"
#include "query/region_extract.h"
#include "scene/scan_set.h"
#include "shard_client/shard_queries.h"
#include "shard_client/shard_roster.h"
#include "shard_set_run.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr double kRes = 0.2;
constexpr int kShards = 3;
const char* kNs = "fleet";
const char* kToken = "shards-edit-token-0123";

// Every n-th end point of the scans, as x y z floats.
std::vector<float> end_points(const ScanSet& set, size_t stride) {
  std::vector<float> xyz;
  for (const PosedScan& s : set.scans) {
    const octomap::Pointcloud w = world_points(s);
    for (size_t i = 0; i < w.size(); i += stride) xyz.insert(xyz.end(), {w[i].x(), w[i].y(), w[i].z()});
  }
  return xyz;
}

TEST(ShardsIntegration, ThreeShardsServeOneMapAndSayWhenOneIsMissing) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  ShardSetRun run("shards");
  ASSERT_TRUE(run.netns().ok()) << run.netns().error();
  // On 2 loaded cores 300 rays may pass the 10 ms lock bound and be cut.
  ASSERT_TRUE(run.start(kNs, kShards, kRes, {"--query-lock-ms", "2000", "--control-token", kToken}));
  const std::string &dir = run.dir, &client_url = run.client_url;
  auto& shards = run.shards;
  for (size_t k = 0; k < scans.scans.size(); ++k) run.publish(scans.scans[k], static_cast<int64_t>(k));
  const int64_t n = static_cast<int64_t>(scans.scans.size());
  ASSERT_TRUE(run.all_applied(n, 120));  // every shard applies every scan (each keeps its own regions' voxels)
  const auto reference = octomap_reference(scans, kRes, -1.0);

  // The merged map, through the CLI: OctoMap's map of the scans (its .bt: max likelihood).
  ChildProcess get({client_program(), "map", "get", "--shards", "--namespace", kNs, "--lcm-url", client_url, "-o",
                    dir + "/merged.bt", "--timeout", "30", "--json"},
                   dir + "/get.log");
  ASSERT_EQ(get.wait(60), 0) << get.log();
  EXPECT_NE(get.log().find("\"partial\": false"), std::string::npos) << get.log();
  EXPECT_NE(get.log().find("\"snapshot_id\": 3"), std::string::npos) << get.log();
  octomap::OcTree merged(kRes);
  ASSERT_TRUE(merged.readBinary(dir + "/merged.bt"));
  octomap::OcTree want(*reference);
  want.toMaxLikelihood();
  want.prune();
  const TreeDiff d = compare_leaves(merged, want);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
  EXPECT_GT(d.leaves_a, 10000u);

  // The shards side by side.
  ChildProcess stat({client_program(), "status", "--shards", "--namespace", kNs, "--lcm-url", client_url, "--json"},
                    dir + "/status.log");
  ASSERT_EQ(stat.wait(30), 0) << stat.log();
  EXPECT_NE(stat.log().find("\"count\": 3"), std::string::npos) << stat.log();
  EXPECT_NE(stat.log().find("\"shortfall\": \"\""), std::string::npos) << stat.log();
  // --watch: one screen a refresh, each with every shard (two here, then it stops).
  ChildProcess watch({client_program(), "status", "--watch", "--shards", "--count", "2", "--namespace", kNs,
                      "--lcm-url", client_url, "--json"},
                     dir + "/watch.log");
  ASSERT_EQ(watch.wait(30), 0) << watch.log();
  size_t screens = 0;
  for (size_t at = 0; (at = watch.log().find("\"count\": 3", at)) != std::string::npos; ++at) ++screens;
  EXPECT_EQ(screens, 2u) << watch.log();

  // Points and rays routed by region: OctoMap's answers.
  const client::ShardRoster roster = client::discover_shards(client_url, kNs, 5);
  ASSERT_TRUE(roster.complete()) << roster.shortfall(now_utime(), 3);
  client::ShardQueries q(client_url, "planner", std::chrono::seconds(3), kNs, *roster.set(), roster.resolution());
  const std::vector<float> xyz = end_points(scans, 50);
  const auto points = q.points(xyz, 0);
  ASSERT_FALSE(points.shards.partial()) << points.shards.shortfall();
  const auto truth = query::query_points(*reference, xyz, 0);
  int differing = 0;
  for (size_t i = 0; i < truth.size(); ++i)
    differing +=
        points.reply.occupancy[i] != int8_t(truth[i].state) || points.reply.probability[i] != truth[i].probability;
  EXPECT_EQ(differing, 0) << "of " << truth.size() << " points";
  std::vector<float> origins, directions;
  for (size_t i = 0; i + 3 <= xyz.size() && origins.size() < 3 * 300; i += 3 * 7) {
    const octomap::point3d o = sensor_origin(scans.scans[0]);
    origins.insert(origins.end(), {o.x(), o.y(), o.z()});
    directions.insert(directions.end(), {xyz[i] - o.x(), xyz[i + 1] - o.y(), xyz[i + 2] - o.z()});
  }
  // Rays passing unknown space, and stopping at it (each shard stops in its own regions only).
  for (const bool ignore_unknown : {true, false}) {
    const auto rays = q.rays(origins, directions, 60.0f, ignore_unknown);
    ASSERT_FALSE(rays.shards.partial()) << rays.shards.shortfall();
    EXPECT_EQ(rays.reply.cut, 0) << rays.reply.error;
    query::RayBatchOptions opt;
    opt.ignore_unknown = ignore_unknown, opt.max_range = 60.0;
    const auto cast = query::cast_rays(*reference, origins, directions, opt);
    ASSERT_EQ(rays.reply.num_rays, static_cast<int32_t>(cast.size()));
    int ray_differing = 0, hits = 0;
    for (size_t i = 0; i < cast.size(); ++i) {
      hits += cast[i].hit;
      ray_differing += rays.reply.hit[i] != cast[i].hit || rays.reply.end_xyz[3 * i] != cast[i].end.x() ||
                       rays.reply.end_xyz[3 * i + 1] != cast[i].end.y() ||
                       rays.reply.end_xyz[3 * i + 2] != cast[i].end.z() ||
                       rays.reply.end_state[i] != int8_t(cast[i].end_state);
    }
    EXPECT_EQ(ray_differing, 0) << "of " << cast.size() << " rays, ignore unknown " << ignore_unknown << "; cut "
                                << int(rays.reply.cut) << " at " << rays.reply.cut_at << ": " << rays.reply.error;
    EXPECT_GT(hits, static_cast<int>(cast.size() / (ignore_unknown ? 2 : 10)));
  }

  // Distances routed to the shards within reach, the smallest of theirs: the distance on
  // OctoMap's map (server/distance/ on it is the one daemon's answer: distance_query_test).
  const std::vector<float> near(xyz.begin(), xyz.begin() + std::min<size_t>(xyz.size(), 3 * 400));
  for (const bool unknown_occupied : {false, true}) {
    client::DistanceRequest dr;
    dr.max_distance = 1.5, dr.gradient = true, dr.unknown_occupied = unknown_occupied;
    distance::DistanceOptions opt;
    opt.max_distance = dr.max_distance;
    opt.unknown = unknown_occupied ? distance::UnknownAs::kOccupied : distance::UnknownAs::kFree;
    const auto dp = q.distance_points(near, dr);
    ASSERT_FALSE(dp.shards.partial()) << dp.shards.shortfall();
    ASSERT_EQ(dp.reply.status, 0) << dp.reply.error;
    const auto want = distance::answer_points(distance::read_points(*reference, near, opt, {}), distance::cpu_edt(1));
    ASSERT_EQ(dp.reply.distance.size(), want.size());
    int differing_points = 0;
    for (size_t p = 0; p < want.size(); ++p) {
      differing_points += dp.reply.distance[p] != want[p].distance;
      for (int a = 0; a < 3; ++a) differing_points += dp.reply.gradient[3 * p + a] != want[p].gradient[a];
    }
    EXPECT_EQ(differing_points, 0) << "of " << want.size() << " points, unknown occupied " << unknown_occupied;
    const client::Box box{{-3.0, -3.0, -0.6}, {3.0, 3.0, 1.0}};
    const auto db = q.distance_box(box, dr);
    ASSERT_FALSE(db.shards.partial()) << db.shards.shortfall();
    ASSERT_EQ(db.reply.header.status, 0) << db.reply.header.error;
    const auto wb =
        distance::answer_box(distance::read_box(*reference, box.min, box.max, opt, {}), distance::cpu_edt(1), true);
    EXPECT_EQ(db.reply.squared, wb.squared);
    EXPECT_EQ(db.reply.gradient, wb.gradient);
  }
  // The CLI's path across the shards: the clearance on OctoMap's map.
  ChildProcess path({client_program(), "query", "distance", "path", "--shards", "--namespace", kNs, "--lcm-url",
                     client_url, "--max", "1.5", "--json", "-3,-3,0.2", "3,3,0.4"},
                    dir + "/path.log");
  ASSERT_EQ(path.wait(30), 0) << path.log();
  distance::DistanceOptions path_opt;
  path_opt.max_distance = 1.5;
  const std::vector<double> vertices = {-3, -3, 0.2, 3, 3, 0.4};
  const auto clearance =
      distance::answer_path(distance::read_path(*reference, vertices, path_opt, {}), distance::cpu_edt(1));
  EXPECT_NE(path.log().find("\"min_sample\": " + std::to_string(clearance.min_sample) + ","), std::string::npos)
      << path.log() << " want sample " << clearance.min_sample;

  // A grid of a band merged from every shard: OctoMap's projected map of the band, on the map's extent.
  const auto grid = q.grid(-0.5, 1.0, 0, nullptr);
  ASSERT_FALSE(grid.shards.partial()) << grid.shards.shortfall();
  ASSERT_EQ(grid.reply.header.status, 0) << grid.reply.header.error;
  query::GridRequest band;
  band.z_min = -0.5, band.z_max = 1.0;
  const query::Grid2D want_grid = query::projected_grid(*reference, band);
  EXPECT_EQ(grid.reply.header.width, want_grid.width);
  EXPECT_EQ(grid.reply.header.height, want_grid.height);
  EXPECT_DOUBLE_EQ(grid.reply.header.origin_x, want_grid.origin_x);
  EXPECT_DOUBLE_EQ(grid.reply.header.origin_y, want_grid.origin_y);
  if (grid.reply.cells.size() == want_grid.cells.size()) {
    size_t differing_cells = 0;
    for (size_t c = 0; c < want_grid.cells.size(); ++c)
      differing_cells += grid.reply.cells[c] != int8_t(want_grid.cells[c]);
    EXPECT_EQ(differing_cells, 0u) << "of " << want_grid.cells.size() << " cells";
  }

  // A box's nodes (region lists) from the shards owning a region of it: the box's voxels each in
  // the state of its node, as in OctoMap's nodes of the box at that depth (begin_leafs_bbx), at
  // the finest depth and at one coarser than the shards' regions (a node several shards hold
  // parts of: occupied when any part is). Compared voxel by voxel: where OctoMap pruned
  // siblings of different shards' regions into one leaf, the shards list the siblings.
  {
    const double lo[3] = {-2.0, -2.0, -0.4}, hi[3] = {2.0, 2.0, 0.8};
    const client::Box region_box{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
    const query::KeyBox kb = query::key_box(*reference, lo, hi);
    using Voxels = std::map<std::array<int, 3>, int>;  // key -> state
    auto add = [&](Voxels& v, int depth, const octomap::point3d& center, int state) {
      const query::NodeCube c = query::node_cube(reference->coordToKey(center), unsigned(depth), 16);
      for (int x = std::max<int>(c.lo[0], kb.min[0]); x <= std::min<int>(c.lo[0] + c.side - 1, kb.max[0]); ++x)
        for (int y = std::max<int>(c.lo[1], kb.min[1]); y <= std::min<int>(c.lo[1] + c.side - 1, kb.max[1]); ++y)
          for (int z = std::max<int>(c.lo[2], kb.min[2]); z <= std::min<int>(c.lo[2] + c.side - 1, kb.max[2]); ++z)
            EXPECT_TRUE(v.emplace(std::array<int, 3>{x, y, z}, state).second) << "a voxel in two nodes";
    };
    for (const int depth : {0, 11}) {
      const auto got = q.region(region_box, depth, true);
      ASSERT_FALSE(got.shards.partial()) << got.shards.shortfall();
      ASSERT_EQ(got.reply.status, 0) << got.reply.error;
      query::RegionOptions ro;
      ro.depth = depth, ro.include_free = true;
      Voxels routed_voxels, want_voxels;
      for (int32_t i = 0; i < got.reply.num_voxels; ++i)
        add(routed_voxels, got.reply.depth[i],
            {got.reply.center_xyz[3 * i], got.reply.center_xyz[3 * i + 1], got.reply.center_xyz[3 * i + 2]},
            got.reply.state[i]);
      for (const auto& v : query::extract_region(*reference, kb, ro)) add(want_voxels, v.depth, v.center, int(v.state));
      EXPECT_GT(want_voxels.size(), 100u) << "depth " << depth;
      EXPECT_TRUE(routed_voxels == want_voxels) << "depth " << depth << ": " << routed_voxels.size()
                                                << " voxels routed, " << want_voxels.size() << " in OctoMap's map";
    }
  }

  // Read-your-writes across the set: a scan shifted into space no scan saw, and at once a routed
  // points query about its end points that waits on every shard for it: OctoMap's map after it
  // (an answer that did not wait finds those points unknown), each shard at a newer state.
  PosedScan unseen = scans.scans[0];
  unseen.pose.trans().x() += 100.0f;
  run.publish(unseen, n);
  const std::vector<float> unseen_xyz = [&] {
    ScanSet one;
    one.scans.push_back(unseen);
    return end_points(one, 50);
  }();
  // Waits may take longer than the 3 s of `q` on loaded cores.
  client::ShardQueries waiting(client_url, "rover", std::chrono::seconds(60), kNs, *roster.set(), roster.resolution());
  client::ShardWait ryw;
  ryw.robot_id = "rover", ryw.seq = n, ryw.timeout_ms = 30000;
  ryw.min_snapshot_ids = points.shards.snapshot_ids;
  const auto fresh = waiting.points(unseen_xyz, 0, ryw);
  ASSERT_FALSE(fresh.shards.partial()) << fresh.shards.shortfall();
  reference->insertPointCloud(world_points(unseen), sensor_origin(unseen), -1.0, false, false);
  const auto fresh_truth = query::query_points(*reference, unseen_xyz, 0);
  int fresh_differing = 0, fresh_occupied = 0;
  for (size_t i = 0; i < fresh_truth.size(); ++i) {
    fresh_differing += fresh.reply.occupancy[i] != int8_t(fresh_truth[i].state) ||
                       fresh.reply.probability[i] != fresh_truth[i].probability;
    fresh_occupied += fresh.reply.occupancy[i] == octomap_rt::occupancy_reply_t::OCC_OCCUPIED;
  }
  EXPECT_EQ(fresh_differing, 0) << "of " << fresh_truth.size() << " points of the scan just sent";
  EXPECT_GT(fresh_occupied, int(0.9 * fresh_truth.size())) << "of " << fresh_truth.size();
  for (uint32_t i = 0; i < uint32_t(kShards); ++i)  // every shard answered from the map with the new scan
    EXPECT_GT(fresh.shards.snapshot_ids[i], points.shards.snapshot_ids[i]) << "shard " << i;
  // A state id a shard cannot reach in time: that shard is named, the answer partial.
  client::ShardWait ahead;
  ahead.timeout_ms = 200;
  ahead.min_snapshot_ids = {0, fresh.shards.snapshot_ids[1] + 1000};
  const auto behind = waiting.points(xyz, 0, ahead);
  EXPECT_EQ(behind.shards.missing, std::vector<uint32_t>{1}) << behind.shards.shortfall();
  // The CLI's --wait-robot with --shards: a scan not sent yet is not waited out (the shard asked
  // answers NOT_READY, named, and no shard answered: exit status 2); one just sent is, and its end
  // point's voxel is occupied.
  PosedScan unseen2 = scans.scans[1];
  unseen2.pose.trans().x() += 200.0f;
  const octomap::point3d end = world_points(unseen2)[0];
  std::vector<std::string> centre;  // the end point's voxel centre, far from a voxel border
  for (int a = 0; a < 3; ++a) centre.push_back(std::to_string((std::floor(end(a) / kRes) + 0.5) * kRes));
  const std::string point = centre[0] + "," + centre[1] + "," + centre[2];
  auto cli_wait = [&](int64_t seq, double timeout_s, const std::string& log) {
    return std::make_unique<ChildProcess>(
        std::vector<std::string>{client_program(), "query", "points", "--shards", "--namespace", kNs, "--lcm-url",
                                 client_url, "--wait-robot", "rover", "--wait-seq", std::to_string(seq), "--timeout",
                                 std::to_string(timeout_s), "--json", point},
        dir + "/" + log);
  };
  auto early = cli_wait(n + 2, 3, "wait_early.log");
  EXPECT_EQ(early->wait(60), 2) << early->log();
  EXPECT_NE(early->log().find("did not answer"), std::string::npos) << early->log();
  run.publish(unseen2, n + 1);
  auto sent = cli_wait(n + 1, 30, "wait_sent.log");
  ASSERT_EQ(sent->wait(60), 0) << sent->log();
  EXPECT_NE(sent->log().find("\"state\": \"occupied\""), std::string::npos) << sent->log();

  // A clear-box inside one region goes to its shard alone; afterwards the box is unknown.
  client::Box clear{};
  uint32_t owner = kShards;
  for (size_t i = 0; i + 3 <= xyz.size() && owner == kShards; i += 3) {
    clear = client::Box{{xyz[i] - 0.3, xyz[i + 1] - 0.3, xyz[i + 2] - 0.3},
                        {xyz[i] + 0.3, xyz[i + 1] + 0.3, xyz[i + 2] + 0.3}};
    const uint32_t lo = q.shard_of_point(clear.min[0], clear.min[1], clear.min[2]);
    if (lo == q.shard_of_point(clear.max[0], clear.max[1], clear.max[2]) &&
        q.shard_of_point(xyz[i], xyz[i + 1], xyz[i + 2]) == lo) {
      const uint32_t shift = 16 - roster.set()->region_depth;
      int64_t k0 = 0, k1 = 0;  // the same region on every axis, not just the same shard
      bool same = true;
      for (int a = 0; a < 3; ++a)
        same = same && client::voxel_key(clear.min[a], kRes, k0) && client::voxel_key(clear.max[a], kRes, k1) &&
               (k0 >> shift) == (k1 >> shift);
      if (same) owner = lo;
    }
  }
  ASSERT_LT(owner, uint32_t(kShards));
  const auto edit = q.edit(octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN, clear, kToken);
  ASSERT_EQ(edit.reply.status, 0) << edit.reply.error;
  for (uint32_t i = 0; i < uint32_t(kShards); ++i)  // asked (a state id) only where the box is
    EXPECT_EQ(edit.shards.snapshot_ids[i] >= 0, i == owner) << "shard " << i;
  const auto after_clear = q.boxes({clear}, octomap_rt::box_query_t::MODE_COUNTS);
  ASSERT_FALSE(after_clear.shards.partial()) << after_clear.shards.shortfall();
  EXPECT_EQ(after_clear.reply.occupied[0] + after_clear.reply.free[0], 0);
  EXPECT_GT(after_clear.reply.unknown[0], 0);
  EXPECT_THROW(
      q.edit(octomap_rt::map_edit_t::OP_CLEAR_TO_FREE, clear, kToken, octomap_rt::map_edit_t::FLAG_INCLUDE_UNKNOWN),
      std::invalid_argument);

  // Shard 2 stops: a merged map and a routed answer say what is missing.
  shards[2]->signal(SIGTERM);
  ASSERT_EQ(shards[2]->wait(60), 0) << shards[2]->log();
  ChildProcess partial({client_program(), "map", "get", "--shards", "--namespace", kNs, "--lcm-url", client_url, "-o",
                        dir + "/partial.bt", "--timeout", "3"},
                       dir + "/partial.log");
  EXPECT_EQ(partial.wait(60), 1) << partial.log();  // without --partial: refused, nothing written
  EXPECT_NE(partial.log().find("shard 2 of 3 missing"), std::string::npos) << partial.log();
  const auto after = q.points(xyz, 0);
  ASSERT_TRUE(after.shards.partial());
  EXPECT_EQ(after.shards.missing, std::vector<uint32_t>{2});
  EXPECT_NE(after.shards.shortfall().find("shard 2 did not answer"), std::string::npos);
  for (auto& s : shards)
    if (s->running()) s->signal(SIGTERM);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(shards[i]->wait(60), 0) << shards[i]->log();
}

}  // namespace
}  // namespace ort::test
