// Serving the map, with real processes in a network namespace (docs/PROTOCOL.md):
//  - a snapshot fetched with `octomap-rt map get` equals the map the server saves and
//    OctoMap's own map of the same scans in the applied order (.ot), and OctoMap's .bt;
//  - under streaming from several robots, mirrors (client library, in this process) end
//    equal to the final snapshot: in class, and in log-odds with --delta-exact; chunks and
//    deltas dropped on purpose in the client's receive path are recovered by re-sends and
//    resyncs (a lost last delta through the next map_info_t), and the same loss without
//    resync leaves the mirror wrong;
//  - bad requests are refused or ignored, counted in the status, and mapping goes on.
#include <gtest/gtest.h>

#include <signal.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "daemon/map/applied_order.h"
#include "daemon/transport/kernel_udp_stats.h"
#include "integration_harness.h"
#include "map_client/map_mirror.h"
#include "octomap_rt/map_request_t.hpp"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

using Chunk = octomap_rt::map_chunk_t;

struct Fixture {
  NetworkNamespace ns;
  std::string dir, url, client_url;
  std::unique_ptr<StatusWatcher> status;
  explicit Fixture(const std::string& tag) : ns(tag) {
    if (!ns.ok()) return;
    dir = make_test_dir(tag);
    url = test_lcm_url(3, ns.rmem_max());
    client_url = url.substr(0, url.find("&recv_buf_size"));  // clients keep the default buffer
    status = std::make_unique<StatusWatcher>(url);
  }
  std::unique_ptr<ChildProcess> server(const std::vector<std::string>& extra) {
    std::vector<std::string> argv{server_program(), "--lcm-url", url, "--chunk-interval-ms", "1.5"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<ChildProcess>(argv, dir + "/server.log");
  }
  std::unique_ptr<ChildProcess> replay(const std::string& input, const std::string& robot,
                                       const std::vector<std::string>& extra) {
    std::vector<std::string> argv{client_program(), "replay", input, "--robot", robot, "--lcm-url", url, "-q"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<ChildProcess>(argv, dir + "/replay-" + robot + ".log");
  }
  bool wait_applied(pid_t pid, int64_t n, double s) {
    return status
        ->wait_for([&](const auto& st) { return st.pid == pid && total_applied(st) == n && st.scan_queue_depth == 0; },
                   s)
        .has_value();
  }
};

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Finest-level class differences: voxels known in one tree only, or occupied in one and
// free in the other (occupancy by each tree's own threshold).
struct ClassDiff {
  uint64_t differing = 0, voxels = 0;
};
ClassDiff compare_classes(const octomap::OcTree& a_in, const octomap::OcTree& b_in) {
  octomap::OcTree a(a_in), b(b_in);
  a.expand();
  b.expand();
  ClassDiff d;
  for (auto it = a.begin_leafs(), end = a.end_leafs(); it != end; ++it) {
    d.voxels++;
    const octomap::OcTreeNode* n = b.search(it.getKey());
    if (!n || a.isNodeOccupied(*it) != b.isNodeOccupied(n)) d.differing++;
  }
  for (auto it = b.begin_leafs(), end = b.end_leafs(); it != end; ++it)
    if (!a.search(it.getKey())) d.differing++;
  return d;
}

TEST(MapServingIntegration, SnapshotEqualsTheSavedMapAndOctomapsOwn) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  Fixture f("mapget");
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  const std::string map = f.dir + "/map.ot";
  auto server = f.server({"-r", "0.2", "--map", map, "--save-interval", "0"});
  ASSERT_TRUE(f.status->wait_for([&](const auto& s) { return s.pid == server->pid(); }, 60)) << server->log();
  const std::vector<std::string> robots{"alpha", "bravo", "charlie"};
  std::vector<std::unique_ptr<ChildProcess>> producers;
  for (size_t i = 0; i < robots.size(); ++i)
    producers.push_back(f.replay(graph, robots[i], {"--first", std::to_string(i), "--count", "1"}));
  for (auto& p : producers) EXPECT_EQ(p->wait(120), 0) << p->log();
  ASSERT_TRUE(f.wait_applied(server->pid(), 3, 240)) << server->log();

  for (const char* ext : {".ot", ".bt"}) {
    ChildProcess get({client_program(), "map", "get", "-o", f.dir + "/snapshot" + ext, "--lcm-url", f.client_url,
                      "--timeout", "60", "-q"},
                     f.dir + "/get" + ext + ".log");
    ASSERT_EQ(get.wait(120), 0) << get.log();
    EXPECT_NE(get.log().find("(3 scans)"), std::string::npos) << get.log();
  }
  server->signal(SIGTERM);
  ASSERT_EQ(server->wait(120), 0) << server->log();

  const daemon::AppliedOrderFile order = daemon::read_applied_order(map + ".order");
  ASSERT_EQ(order.entries.size(), 3u);
  ScanSet applied;
  for (const auto& e : order.entries)
    for (size_t i = 0; i < robots.size(); ++i)
      if (same_robot(e.robot_id, robots[i])) applied.scans.push_back(scans.scans[i]);
  ASSERT_EQ(applied.scans.size(), 3u);
  const auto reference = octomap_reference(applied, 0.2, -1.0);
  const auto snapshot = load_ot(f.dir + "/snapshot.ot");
  const auto saved = load_ot(map);
  ASSERT_TRUE(snapshot && saved);
  for (const octomap::OcTree* other : {saved.get(), reference.get()}) {
    const TreeDiff d = compare_leaves(*snapshot, *other);
    EXPECT_EQ(d.differing_voxels, 0u) << d.first_difference;
    EXPECT_EQ(d.differing_logodds, 0u) << d.first_difference;
  }
  std::ostringstream bt;
  octomap::OcTree ref_copy(*reference);
  ref_copy.writeBinary(bt);
  EXPECT_EQ(read_file(f.dir + "/snapshot.bt"), bt.str()) << "the .bt snapshot differs from OctoMap's .bt";
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

// Datagrams the kernel dropped on this process's sockets (its LCM clients' receive buffers
// full): udpm loses them, and a mirror then sees a gap. 0 when unknown.
int64_t own_drops() { return std::max<int64_t>(0, daemon::read_own_udp_drops()); }

// Runs `mirrors` while 3 robots stream the synthetic scene (`scans_each` each), then
// returns the final snapshot (fetched without loss once everything is applied) once the
// mirrors in `converging` are at its version (a lost last delta is found by the next
// map_info_t, then resynced; at most 15 s).
std::unique_ptr<octomap::OcTree> stream_and_mirror(Fixture& f, ChildProcess& server, int scans_each,
                                                   std::vector<client::MapMirror*> mirrors,
                                                   std::vector<client::MapMirror*> converging,
                                                   const std::function<void()>& while_streaming) {
  for (auto* m : mirrors) m->sync();
  std::vector<std::unique_ptr<ChildProcess>> producers;
  for (int i = 0; i < 3; ++i)
    producers.push_back(
        f.replay("synthetic", "robot" + std::to_string(i),
                 {"--part", std::to_string(i) + "/3", "--repeat", std::to_string(scans_each / 2), "--rate", "8"}));
  bool fetched = false;
  auto running = [&] {
    for (auto& p : producers)
      if (p->running()) return true;
    return false;
  };
  while (running()) {
    for (auto* m : mirrors) m->spin(0.05);
    if (!fetched && while_streaming) {
      while_streaming();
      fetched = true;
    }
  }
  for (auto& p : producers) EXPECT_EQ(p->wait(10), 0) << p->log();
  EXPECT_TRUE(f.wait_applied(server.pid(), 3 * scans_each, 300)) << server.log();
  client::MapClient c(f.client_url);
  const client::FetchedSnapshot final_map = c.fetch_snapshot(Chunk::FORMAT_OCTOMAP_FULL, 60);
  auto behind = [&] {
    for (auto* m : converging)
      if (m->version() < final_map.snapshot_id) return true;
    return false;
  };
  for (int k = 0; k < 300 && behind(); ++k)
    for (auto* m : mirrors) m->spin(0.05);  // the last change sets (10 Hz) and map infos (1 Hz) arrive
  for (auto* m : converging) EXPECT_EQ(m->version(), final_map.snapshot_id);
  return final_map.tree();
}

TEST(MapServingIntegration, MirrorsFollowStreamingAndRecoverFromLoss) {
  Fixture f("mirror");
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  auto server = f.server({"-r", "0.2"});
  ASSERT_TRUE(f.status->wait_for([&](const auto& s) { return s.pid == server->pid(); }, 60)) << server->log();

  client::MapClient clean_client(f.client_url);
  client::MapMirror clean(clean_client);
  int64_t callbacks = 0;
  client::ClientOptions lossy_opts;
  lossy_opts.drop_delta = [](const octomap_rt::map_delta_t& d) { return d.delta_seq % 9 == 2; };
  client::MapClient lossy_client(f.client_url, lossy_opts);
  client::MirrorOptions counted;
  counted.on_delta = [&](const client::AppliedDelta&) { callbacks++; };
  client::MapMirror lossy(lossy_client, counted);
  client::MapClient no_resync_client(f.client_url, lossy_opts);
  client::MirrorOptions off;
  off.resync = false;
  client::MapMirror no_resync(no_resync_client, off);

  // A fetch during streaming that loses every chunk the first time it comes.
  client::FetchedSnapshot lossy_fetch;
  auto fetch_with_loss = [&] {
    std::set<int32_t> seen;
    client::ClientOptions o;
    o.drop_chunk = [&](const Chunk& c) { return seen.insert(c.chunk_index).second; };
    client::MapClient c(f.client_url, o);
    lossy_fetch = c.fetch_snapshot(Chunk::FORMAT_OCTOMAP_FULL, 60);
  };
  const auto final_map =
      stream_and_mirror(f, *server, 40, {&clean, &lossy, &no_resync}, {&clean, &lossy}, fetch_with_loss);
  auto show = [](const char* name, const client::MapMirror& m, const ClassDiff& d) {
    const client::MirrorStats& s = m.stats();
    std::cout << name << ": version " << m.version() << ", " << s.deltas_applied << " deltas applied ("
              << s.voxels_applied << " voxels), " << s.gaps << " gaps, " << s.snapshots << " snapshots; " << d.differing
              << " of " << d.voxels << " voxels differ in class from the final snapshot\n";
  };
  show("clean", clean, compare_classes(clean.tree(), *final_map));
  show("lossy", lossy, compare_classes(lossy.tree(), *final_map));
  show("no resync", no_resync, compare_classes(no_resync.tree(), *final_map));
  std::cout << "lossy fetch: " << lossy_fetch.requests << " requests, " << lossy_fetch.chunks_dropped << " of "
            << lossy_fetch.num_chunks << " chunks dropped once\n";
  EXPECT_GE(lossy_fetch.requests, 2);
  EXPECT_EQ(lossy_fetch.chunks_dropped, lossy_fetch.num_chunks);

  const ClassDiff d_clean = compare_classes(clean.tree(), *final_map);
  EXPECT_EQ(d_clean.differing, 0u) << "of " << d_clean.voxels;
  if (own_drops() == 0) {
    EXPECT_EQ(clean.stats().gaps, 0) << "gaps without a datagram dropped by the kernel";
  }
  EXPECT_GT(clean.stats().deltas_applied, 10);
  const ClassDiff d_lossy = compare_classes(lossy.tree(), *final_map);
  EXPECT_EQ(d_lossy.differing, 0u) << "of " << d_lossy.voxels;
  EXPECT_GT(lossy.stats().gaps, 0);
  EXPECT_GT(lossy.stats().snapshots, 1);
  EXPECT_EQ(callbacks, lossy.stats().deltas_applied);
  EXPECT_GT(no_resync.stats().gaps, 0);
  EXPECT_GT(compare_classes(no_resync.tree(), *final_map).differing, 0u) << "losing deltas without resync went unseen";
  server->signal(SIGTERM);
  EXPECT_EQ(server->wait(120), 0) << server->log();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

TEST(MapServingIntegration, ExactMirrorEqualsTheFinalSnapshotInLogOdds) {
  Fixture f("exact");
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  auto server = f.server({"-r", "0.2", "--delta-exact"});
  ASSERT_TRUE(f.status->wait_for([&](const auto& s) { return s.pid == server->pid(); }, 60)) << server->log();
  client::MapClient c(f.client_url);
  client::MapMirror mirror(c);
  const auto final_map = stream_and_mirror(f, *server, 36, {&mirror}, {&mirror}, {});
  const TreeDiff d = compare_leaves(mirror.tree(), *final_map);
  EXPECT_EQ(d.differing_voxels, 0u) << d.first_difference;
  EXPECT_EQ(d.differing_logodds, 0u) << d.first_difference;
  // The deltas carried the log-odds (no resync snapshot did), unless the kernel dropped some.
  const int64_t drops = own_drops();
  if (drops == 0) {
    EXPECT_EQ(mirror.stats().gaps, 0) << "gaps without a datagram dropped by the kernel";
  }
  std::cout << "exact mirror: " << mirror.stats().deltas_applied << " deltas applied, " << mirror.stats().gaps
            << " gaps, " << drops << " datagrams dropped by the kernel on this process's sockets\n";
  EXPECT_GT(mirror.stats().deltas_applied, 10);
  server->signal(SIGTERM);
  EXPECT_EQ(server->wait(120), 0) << server->log();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

TEST(MapServingIntegration, BadRequestsAreCountedAndMappingGoesOn) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  Fixture f("badreq");
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  auto server = f.server({"-r", "0.2"});
  ASSERT_TRUE(f.status->wait_for([&](const auto& s) { return s.pid == server->pid(); }, 60)) << server->log();
  lcm::LCM lc(f.client_url);
  ASSERT_TRUE(lc.good());
  auto send = [&](const octomap_rt::map_request_t& r) {
    std::vector<uint8_t> b(r.getEncodedSize());
    r.encode(b.data(), 0, static_cast<int>(b.size()));
    lc.publish("OCTOMAP_RT_MAP_REQUEST", b.data(), static_cast<unsigned>(b.size()));
    return b;
  };
  octomap_rt::map_request_t good{};
  good.format = Chunk::FORMAT_OCTOMAP_FULL;
  good.client_id = "tester";
  good.reply_channel = "OCTOMAP_RT_MAP_REPLY_TESTER";
  int64_t bad = 0;
  {
    auto r = good;
    r.format = 9;
    send(r);
    ++bad;
  }  // unknown format
  {
    auto r = good;
    r.chunk_indices = {-4};
    r.num_chunk_indices = 1;
    send(r);
    ++bad;
  }  // negative index
  {
    auto r = good;
    r.chunk_indices = {100000};
    r.num_chunk_indices = 1;
    send(r);
    ++bad;
  }  // out of range
  {
    auto r = good;
    r.snapshot_id = 987654;
    send(r);
    ++bad;
  }  // not kept
  {
    auto r = good;
    r.client_id = "bad id!";
    send(r);
    ++bad;
  }  // bad string
  {
    auto r = good;
    r.reply_channel = "OCTOMAP_RT_SCAN_X";
    send(r);
    ++bad;
  }  // not a reply channel
  {
    auto r = good;
    r.chunk_indices.assign(9000, 1);  // more than a request may name
    r.num_chunk_indices = 9000;
    send(r);
    ++bad;
  }
  {
    auto b = send(good);  // a good one, then its bytes with a negative count
    b[33] = 0xff;
    lc.publish("OCTOMAP_RT_MAP_REQUEST", b.data(), static_cast<unsigned>(b.size()));
    ++bad;
  }
  for (int i = 0; i < 300; ++i) {  // a flood: refused as busy beyond the queue, or served
    auto r = good;
    r.request_id = 1000 + i;
    r.format = 42;
    send(r);
    ++bad;
  }
  ASSERT_TRUE(
      f.status->wait_for([&](const auto& s) { return s.pid == server->pid() && s.requests_rejected >= bad; }, 60))
      << "rejected " << (f.status->latest() ? f.status->latest()->requests_rejected : -1) << " of " << bad << "\n"
      << server->log();
  auto p = f.replay(graph, "alpha", {"--first", "0", "--count", "1"});
  EXPECT_EQ(p->wait(120), 0) << p->log();
  EXPECT_TRUE(f.wait_applied(server->pid(), 1, 240)) << server->log();
  client::MapClient c(f.client_url);
  EXPECT_EQ(c.fetch_snapshot(Chunk::FORMAT_OCTOMAP_BINARY, 60).num_scans, 1);
  EXPECT_THROW(
      {
        client::ClientOptions o;
        o.request_channel = "OCTOMAP_RT_NOBODY_LISTENS";
        client::MapClient lonely(f.client_url, o);
        lonely.fetch_snapshot(Chunk::FORMAT_OCTOMAP_FULL, 1.0);
      },
      client::FetchError);
  server->signal(SIGTERM);
  EXPECT_EQ(server->wait(120), 0) << server->log();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

}  // namespace
}  // namespace ort::test
