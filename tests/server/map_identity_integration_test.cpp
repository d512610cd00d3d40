// A mirror across server restarts, with real processes in a network namespace
// (docs/PROTOCOL.md "Ids" and "Resync"): after an orderly stop and a start on the same map
// file the server keeps epoch and state id, and a mirror at that id goes on with the new
// server's deltas without another snapshot; after a crash (SIGKILL) the server comes back in
// a new epoch and the mirror resyncs. Either way the mirror ends equal to the server's map.
#include <gtest/gtest.h>

#include <signal.h>

#include <filesystem>

#include "integration_harness.h"
#include "map_client/map_mirror.h"

namespace ort::test {
namespace {

using Chunk = octomap_rt::map_chunk_t;

struct Fixture {
  NetworkNamespace ns{"identity"};
  std::string dir, url, client_url, map;
  std::unique_ptr<StatusWatcher> status;
  Fixture() {
    if (!ns.ok()) return;
    dir = make_test_dir("identity");
    map = dir + "/map.ot";
    url = test_lcm_url(3, ns.rmem_max());
    client_url = url.substr(0, url.find("&recv_buf_size"));
    status = std::make_unique<StatusWatcher>(url);
  }
  std::unique_ptr<ChildProcess> server(int run) {
    return std::make_unique<ChildProcess>(
        std::vector<std::string>{server_program(), "--lcm-url", url, "-r", "0.2", "--map", map, "--save-interval",
                                 "0.5", "--chunk-interval-ms", "1.5"},
        dir + "/server-" + std::to_string(run) + ".log");
  }
  // Robot "rover" streams the 6 synthetic scans `repeat` times, seqs from `first_seq`, while
  // the mirror follows; returns once the server has applied them all.
  void stream(ChildProcess& server, client::MapMirror& mirror, int first_seq, int repeat) {
    const int64_t total = 6 * repeat;
    ChildProcess replay({client_program(), "replay", "synthetic", "--robot", "rover", "--lcm-url", url, "-q",
                         "--repeat", std::to_string(repeat), "--first-seq", std::to_string(first_seq), "--rate", "10"},
                        dir + "/replay.log");
    while (replay.running()) mirror.spin(0.05);
    EXPECT_EQ(replay.wait(10), 0) << replay.log();
    EXPECT_TRUE(status->wait_for(
        [&](const auto& st) {
          return st.pid == server.pid() && total_applied(st) == total && st.scan_queue_depth == 0;
        },
        120))
        << server.log();
  }
  octomap_rt::server_status_t running(ChildProcess& server) {
    const auto st = status->wait_for([&](const auto& s) { return s.pid == server.pid() && s.state == 1; }, 60);
    EXPECT_TRUE(st.has_value()) << server.log();
    return st.value_or(octomap_rt::server_status_t{});
  }
};

// The mirror catches up with the server's snapshot now, and equals it (class per voxel).
void expect_mirror_equals_server(Fixture& f, client::MapMirror& mirror) {
  client::MapClient c(f.client_url);
  const client::FetchedSnapshot now = c.fetch_snapshot(Chunk::FORMAT_OCTOMAP_FULL, 60);
  for (int k = 0; k < 300 && (mirror.version() < now.snapshot_id || mirror.epoch() != now.map_epoch); ++k)
    mirror.spin(0.05);
  EXPECT_EQ(mirror.epoch(), now.map_epoch);
  ASSERT_EQ(mirror.version(), now.snapshot_id);
  auto a = mirror.tree(), b = *now.tree();
  a.expand();
  b.expand();
  uint64_t differing = 0, voxels = 0;
  for (auto it = a.begin_leafs(); it != a.end_leafs(); ++it, ++voxels) {
    const octomap::OcTreeNode* n = b.search(it.getKey());
    if (!n || a.isNodeOccupied(*it) != b.isNodeOccupied(n)) differing++;
  }
  for (auto it = b.begin_leafs(); it != b.end_leafs(); ++it)
    if (!a.search(it.getKey())) differing++;
  EXPECT_EQ(differing, 0u) << "of " << voxels;
}

TEST(MapIdentityIntegration, AMirrorGoesOnAcrossACleanRestartAndResyncsAfterACrash) {
  Fixture f;
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  auto first = f.server(1);
  const auto st1 = f.running(*first);
  client::MapClient mc(f.client_url);
  client::MapMirror mirror(mc);
  mirror.sync();
  f.stream(*first, mirror, 0, 2);
  expect_mirror_equals_server(f, mirror);
  const int64_t epoch = mirror.epoch(), version = mirror.version();
  EXPECT_EQ(epoch, st1.map_epoch);
  first->signal(SIGTERM);
  ASSERT_EQ(first->wait(60), 0) << first->log();

  // Clean restart: same epoch and id; the mirror applies the new server's deltas on.
  auto second = f.server(2);
  const auto st2 = f.running(*second);
  EXPECT_EQ(st2.map_epoch, epoch);
  EXPECT_EQ(st2.map_version, version);
  const int64_t snapshots = mirror.stats().snapshots;
  f.stream(*second, mirror, 12, 1);
  expect_mirror_equals_server(f, mirror);
  EXPECT_EQ(mirror.epoch(), epoch);
  EXPECT_EQ(mirror.stats().snapshots, snapshots) << "no resync needed after a clean restart";
  EXPECT_GT(mirror.version(), version);

  // A crash: a new epoch, and the mirror resyncs to the map the new server has.
  second->signal(SIGKILL);
  second->wait(30);
  auto third = f.server(3);
  const auto st3 = f.running(*third);
  EXPECT_NE(st3.map_epoch, epoch);
  f.stream(*third, mirror, 18, 1);
  expect_mirror_equals_server(f, mirror);
  EXPECT_EQ(mirror.epoch(), st3.map_epoch);
  EXPECT_GT(mirror.stats().epoch_changes, 0);
  EXPECT_GT(mirror.stats().snapshots, snapshots);

  // And a second daemon on the same map is refused, saying who holds it.
  auto intruder = f.server(4);
  EXPECT_EQ(intruder->wait(60).value_or(-1) != 0, true);
  EXPECT_NE(intruder->log().find("in use by pid " + std::to_string(third->pid())), std::string::npos)
      << intruder->log();
  third->signal(SIGTERM);
  EXPECT_EQ(third->wait(60), 0) << third->log();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

}  // namespace
}  // namespace ort::test
