// Every shard's deltas in one mirror (client/shard_client/shard_mirror.h), with real processes
// in a network namespace: three octomap-rt-server --shard i/3 hear a robot's real scans (3DTK)
// over udpm while a ShardMirror follows them. The merged mirror equals the shards' merged
// snapshot and OctoMap's map of the scans (one producer: every shard's applied order is the
// scans' order), each shard's part followed by deltas, not by snapshots. A reset of one shard
// (a new epoch) resyncs that shard alone; a stopped shard is said late, one never fetched missing,
// and `octomap-rt map watch --shards --save` writes the same merged map.
#include <gtest/gtest.h>

#include <signal.h>

#include "core/clock.h"
#include "scene/scan_set.h"
#include "shard_client/shard_mirror.h"
#include "shard_client/shard_roster.h"
#include "shard_client/shard_snapshot.h"
#include "shard_set_run.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr double kRes = 0.2;
constexpr int kShards = 3;
const char* kNs = "fleet";
const char* kToken = "shards-mirror-token-0123";

// A map's classes as a mirror that got them all from class-mode deltas holds them (the clamping
// bounds). A mirror synced on a map with voxels holds the snapshot's log-odds beside them.
std::unique_ptr<octomap::OcTree> max_likelihood(const octomap::OcTree& t) {
  auto out = std::make_unique<octomap::OcTree>(t);
  out->toMaxLikelihood();
  out->prune();
  return out;
}

// Spins `m` until every shard's part is at the state id of its fresh snapshot in `merged`, and
// at least 1.5 s: every shard's map info (1 Hz) heard afresh, so none is late for the time the
// test spent elsewhere without spinning (late: no map info for 3 s).
bool catch_up(client::ShardMirror& m, const client::MergedMap& merged, double timeout_s) {
  const auto t0 = SteadyClock::now();
  m.spin(1.5);
  auto caught_up = [&] {
    for (const client::ShardMirrorPart& p : m.parts())
      if (p.version != merged.parts[p.index].snapshot_id || p.epoch != merged.parts[p.index].epoch) return false;
    return true;
  };
  while (!caught_up() && seconds_since(t0) < timeout_s) m.spin(0.2);
  return caught_up();
}

void expect_same_map(const octomap::OcTree& mirror, const octomap::OcTree& want, const char* what) {
  octomap::OcTree pruned(mirror);
  pruned.prune();
  const TreeDiff d = compare_leaves(pruned, want);
  EXPECT_TRUE(d.maps_equal()) << what << ": " << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
}

TEST(ShardMirrorIntegration, OneMirrorFollowsEveryShardResyncsOneAndSaysWhichIsLate) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  ShardSetRun run("shard_mirror");
  ASSERT_TRUE(run.netns().ok()) << run.netns().error();
  ASSERT_TRUE(run.start(kNs, kShards, kRes, {"--control-token", kToken}));
  const std::string &dir = run.dir, &url = run.url, &client_url = run.client_url;
  auto& shards = run.shards;

  const client::ShardRoster roster = client::discover_shards(url, kNs, 5);
  ASSERT_TRUE(roster.complete()) << roster.shortfall(now_utime(), 3);
  client::ShardMirror mirror(url, kNs, *roster.set());
  mirror.sync();  // the empty maps: every scan below reaches the mirror as deltas
  ASSERT_EQ(mirror.shortfall(now_utime()), "");

  for (size_t k = 0; k < scans.scans.size(); ++k) {
    run.publish(scans.scans[k], static_cast<int64_t>(k));
    mirror.spin(0.3);
  }
  const int64_t n = static_cast<int64_t>(scans.scans.size());
  ASSERT_TRUE(run.all_applied(n, 120));

  // The merged mirror = the shards' merged snapshot = OctoMap's map of the scans.
  client::MergedMap snap = client::fetch_merged_map(client_url, kNs, roster, 30);
  ASSERT_FALSE(snap.partial) << snap.shortfall;
  ASSERT_TRUE(catch_up(mirror, snap, 30)) << mirror.shortfall(now_utime());
  client::MergedMirror merged = mirror.merged(now_utime());
  ASSERT_TRUE(merged.tree);
  EXPECT_FALSE(merged.partial());
  EXPECT_EQ(merged.shortfall, "");
  expect_same_map(*merged.tree, *max_likelihood(*snap.tree), "mirror vs merged snapshot");
  const auto reference = octomap_reference(scans, kRes, -1.0);
  const auto want = max_likelihood(*reference);
  expect_same_map(*merged.tree, *want, "mirror vs OctoMap");
  EXPECT_GT(want->getNumLeafNodes(), 10000u);
  for (const client::ShardMirrorPart& p : mirror.parts()) {  // followed by deltas, each shard its own chain
    EXPECT_EQ(p.stats.snapshots, 1) << "shard " << p.index;
    EXPECT_GT(p.stats.deltas_applied, 0) << "shard " << p.index;
    EXPECT_GT(p.stats.voxels_applied, 1000) << "shard " << p.index;
    EXPECT_EQ(p.refused_infos, 0) << "shard " << p.index;
  }
  const int64_t epoch1 = mirror.parts()[1].epoch;

  // Shard 1 alone is reset (a new epoch), then maps one more scan: the mirror resyncs shard 1
  // only and again equals the merged snapshot.
  ChildProcess reset({client_program(), "map", "reset", "--namespace", std::string(kNs) + "_SHARD1", "--lcm-url",
                      client_url, "--token", kToken, "--timeout", "10"},
                     dir + "/reset.log");
  ASSERT_EQ(reset.wait(30), 0) << reset.log();
  mirror.spin(1.5);
  run.publish(scans.scans[0], n);
  ASSERT_TRUE(run.all_applied(n + 1, 120));
  snap = client::fetch_merged_map(client_url, kNs, roster, 30);
  ASSERT_FALSE(snap.partial) << snap.shortfall;
  ASSERT_TRUE(catch_up(mirror, snap, 30)) << mirror.shortfall(now_utime());
  merged = mirror.merged(now_utime());
  // Shard 1's part is its new snapshot (log-odds, if the scan came first) and deltas: by class.
  expect_same_map(*max_likelihood(*merged.tree), *max_likelihood(*snap.tree), "after shard 1's reset");
  const auto parts = mirror.parts();
  EXPECT_NE(parts[1].epoch, epoch1);
  EXPECT_GE(parts[1].stats.epoch_changes, 1);
  EXPECT_EQ(parts[1].stats.snapshots, 2);
  EXPECT_EQ(parts[0].stats.snapshots, 1);
  EXPECT_EQ(parts[2].stats.snapshots, 1);

  // The CLI's watch of the set saves the same merged map.
  ChildProcess watch({client_program(), "map", "watch", "--shards", "--namespace", kNs, "--lcm-url", client_url,
                      "--seconds", "2", "--json", "--save", dir + "/watched.ot"},
                     dir + "/watch.log");
  ASSERT_EQ(watch.wait(60), 0) << watch.log();
  EXPECT_NE(watch.log().find("\"partial\": false"), std::string::npos) << watch.log();
  std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(dir + "/watched.ot"));
  auto* watched = dynamic_cast<octomap::OcTree*>(read.get());
  ASSERT_TRUE(watched) << watch.log();
  expect_same_map(*max_likelihood(*watched), *max_likelihood(*snap.tree), "map watch --shards --save");

  // Shard 2 stops: the mirror says it is late; a new mirror says it is missing.
  shards[2]->signal(SIGTERM);
  ASSERT_EQ(shards[2]->wait(60), 0) << shards[2]->log();
  mirror.spin(4.0);
  merged = mirror.merged(now_utime());
  EXPECT_EQ(merged.late, std::vector<uint32_t>{2});
  EXPECT_NE(merged.shortfall.find("shard 2 of 3 late (no map info for"), std::string::npos) << merged.shortfall;
  client::ShardMirrorOptions quick;
  quick.mirror.fetch_timeout_s = 2;
  client::ShardMirror fresh(url, kNs, *roster.set(), quick);
  fresh.sync();
  const client::MergedMirror without = fresh.merged(now_utime());
  EXPECT_TRUE(without.partial());
  EXPECT_EQ(without.missing, std::vector<uint32_t>{2});
  EXPECT_NE(without.shortfall.find("shard 2 of 3 missing"), std::string::npos) << without.shortfall;
  ChildProcess partial_watch({client_program(), "map", "watch", "--shards", "--namespace", kNs, "--lcm-url", client_url,
                              "--seconds", "1", "--timeout", "2"},
                             dir + "/partial_watch.log");
  EXPECT_EQ(partial_watch.wait(60), 3) << partial_watch.log();
  EXPECT_NE(partial_watch.log().find("PARTIAL: shard 2 of 3 missing"), std::string::npos) << partial_watch.log();
  for (int i = 0; i < 2; ++i) {
    shards[i]->signal(SIGTERM);
    EXPECT_EQ(shards[i]->wait(60), 0) << shards[i]->log();
  }
}

}  // namespace
}  // namespace ort::test
