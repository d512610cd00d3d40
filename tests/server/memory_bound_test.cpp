// The memory bound in the daemon (--max-map-memory, daemon/map/map_residency.h), as users
// meet it: real scans go in past the bound, the tree's memory stays under it, and the map
// that comes out (snapshot copy, saved file, a restart, a restart after kill -9) is OctoMap's
// own map of the same scans, voxel for voxel and log-odds for log-odds.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "daemon/map/applied_order.h"
#include "daemon/persistence/map_identity_file.h"
#include "daemon/persistence/region_store.h"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "octree/decay.h"
#include "query/box_count.h"
#include "query/point_query.h"
#include "scene/scan_set.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

const char* kChannel = "OCTOMAP_RT_SCAN_ALPHA";

// The real 3DTK scans, every kThin-th point of each: the map is still well past the bound's
// 1 MiB floor (regions must go and come back) and OctoMap builds its reference maps in a
// fraction of the time the whole scans take.
constexpr size_t kThin = 6;

const ScanSet& real_scans() {
  static const ScanSet set = [] {
    ScanSet all = load_scan_graph(data_file("3dtk_dat/3dtk_3scans.graph"));
    for (PosedScan& s : all.scans) {
      octomap::Pointcloud kept;
      for (size_t i = 0; i < s.points.size(); i += kThin) kept.push_back(s.points[i]);
      s.points = kept;
    }
    return all;
  }();
  return set;
}

// OctoMap's map of `passes` passes over the scans, in order.
std::unique_ptr<octomap::OcTree> octomap_map(const ScanSet& set, const daemon::ServerConfig& cfg, int passes) {
  ScanSet all;
  for (int p = 0; p < passes; ++p) all.scans.insert(all.scans.end(), set.scans.begin(), set.scans.end());
  return octomap_reference(all, cfg.engine.resolution, cfg.engine.max_range);
}

void expect_octomaps(const octomap::OcTree& map, const octomap::OcTree& reference, const std::string& what) {
  const TreeDiff d = compare_leaves(map, reference);
  EXPECT_TRUE(d.maps_equal()) << what << ": " << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
  EXPECT_GT(d.leaves_b, 10000u) << what;
}

daemon::ServerConfig bounded_config(const std::string& dir, uint64_t bound) {
  auto cfg = test_config(0.1, true);
  cfg.map_path = dir + "/map.ot";
  cfg.max_map_memory = bound;
  // These tests check answers, not the lock bound: a loaded machine (CI's sanitizers) must not
  // cut a box count at the default 10 ms.
  cfg.queries.bounds.lock_ms = 2000;
  return cfg;
}

// Half of OctoMap's map of one pass: regions must go, and come back on the second.
uint64_t tight_bound(const octomap::OcTree& one_pass) {
  return std::max<uint64_t>(one_pass.memoryUsage() / 2, 1u << 20);
}

void send_pass(lcm::LCM& lc, daemon::MappingServer& server, const ScanSet& set, int64_t& sent, uint64_t& most) {
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "alpha", sent);
    lc.publish(kChannel, &msg);
    ASSERT_TRUE(wait_until_done(server, ++sent));
    most = std::max<uint64_t>(most, server.with_map([](const octomap::OcTree& t) { return t.memoryUsage(); }));
  }
}

// The distance (metres, clamped at max_m) from the centre of p's voxel to the nearest occupied
// voxel centre of `tree`, by a search of every occupied leaf: the definition (PROTOCOL.md).
float brute_force_distance(const octomap::OcTree& tree, const octomap::point3d& p, double max_m) {
  const octomap::OcTreeKey k = tree.coordToKey(p);
  int64_t best = -1;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const int64_t side = int64_t(1) << (16 - it.getDepth()), half = side / 2;
    int64_t sq = 0;
    for (int a = 0; a < 3; ++a) {  // the nearest voxel of the leaf's cube, axis by axis
      const int64_t lo = int64_t(it.getKey()[a]) - half, hi = lo + side - 1;
      const int64_t c = k[a], d = c < lo ? lo - c : c > hi ? c - hi : 0;
      sq += d * d;
    }
    if (best < 0 || sq < best) best = sq;
  }
  const double d = best < 0 ? max_m : std::sqrt(double(best)) * tree.getResolution();
  return float(std::min(d, max_m));
}

// Distances into evicted regions: the read brings them back, and the answers are the
// brute-force search's on OctoMap's map.
void expect_distances_answer_as_octomap(lcm::LCM& lc, daemon::MappingServer& server, Replies& replies,
                                        const ScanSet& set, const octomap::OcTree& reference) {
  const uint64_t restores = server.residency_stats().restores;
  ASSERT_GT(server.residency_stats().evicted_regions, 0u);
  octomap_rt::distance_query_t q{};
  address(q, 4);
  q.mode = octomap_rt::distance_query_t::MODE_POINTS, q.max_distance = 1.5, q.cell_voxels = 1;
  for (const PosedScan& scan : set.scans) {
    const octomap::Pointcloud w = world_points(scan);
    for (size_t i = 0; i < w.size(); i += 211) {
      const float shift = 0.07f * float(q.xyz.size() % 13) - 0.4f;
      q.xyz.insert(q.xyz.end(), {w[i].x() + shift, w[i].y() - shift, w[i].z() + 0.5f * shift});
    }
  }
  q.num_xyz = int32_t(q.xyz.size());
  lc.publish(ort::protocol::kQueryDistanceChannel, &q);
  const auto r = replies.wait_for<octomap_rt::distance_points_reply_t>(4);
  ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
  ASSERT_EQ(size_t(r.num_points), q.xyz.size() / 3);
  int differ = 0, near = 0;
  for (int i = 0; i < r.num_points; ++i) {
    const float want = brute_force_distance(
        reference, octomap::point3d(q.xyz[3 * i], q.xyz[3 * i + 1], q.xyz[3 * i + 2]), q.max_distance);
    differ += std::abs(r.distance[i] - want) > 1e-5f;
    near += want < 1.5f;
  }
  EXPECT_EQ(differ, 0) << "of " << r.num_points << " points";
  EXPECT_GT(near, r.num_points / 2);
  EXPECT_GT(server.residency_stats().restores, restores) << "the distance read brought evicted regions back";
}

// Queries into evicted regions: points, rays and boxes answer as OctoMap's map does.
void expect_queries_answer_as_octomap(lcm::LCM& lc, daemon::MappingServer& server, Replies& replies, const ScanSet& set,
                                      const octomap::OcTree& reference) {
  expect_distances_answer_as_octomap(lc, server, replies, set, reference);
  const uint64_t restores = server.residency_stats().restores;
  ASSERT_GT(server.residency_stats().evicted_regions, 0u);
  std::vector<float> pts;
  const octomap::Pointcloud first = world_points(set.scans[0]);
  for (size_t i = 0; i < first.size(); i += 97) pts.insert(pts.end(), {first[i].x(), first[i].y(), first[i].z()});
  const auto pq = point_query(1, pts);
  lc.publish(ort::protocol::kQueryChannel, &pq);
  const Reply pr = replies.wait_for<Reply>(1);
  ASSERT_EQ(pr.status, Reply::REPLY_OK) << pr.error;
  const auto want = query::query_points(reference, pts, 0);
  ASSERT_EQ(size_t(pr.num_results), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(pr.occupancy[i], int8_t(want[i].state)) << "point " << i;
    EXPECT_EQ(pr.probability[i], want[i].probability) << "point " << i;
  }
  octomap_rt::ray_query_t rq{};
  address(rq, 2);
  rq.max_range = 30;
  const octomap::point3d o = sensor_origin(set.scans[0]);
  for (int i = 0; i < 64; ++i) {
    rq.origin_xyz.insert(rq.origin_xyz.end(), {o.x(), o.y(), o.z()});
    rq.direction_xyz.insert(rq.direction_xyz.end(), {std::cos(0.1f * i), std::sin(0.1f * i), -0.05f});
  }
  rq.num_xyz = static_cast<int32_t>(rq.origin_xyz.size());
  lc.publish(ort::protocol::kQueryRaysChannel, &rq);
  const auto rr = replies.wait_for<octomap_rt::ray_reply_t>(2);
  ASSERT_EQ(rr.status, Reply::REPLY_OK) << rr.error;
  for (int i = 0; i < 64; ++i) {
    octomap::point3d end;
    const bool hit =
        reference.castRay(o, octomap::point3d(std::cos(0.1f * i), std::sin(0.1f * i), -0.05f), end, false, 30);
    EXPECT_EQ(rr.hit[i], hit) << "ray " << i;
    EXPECT_EQ(rr.end_xyz[3 * i], end.x()) << "ray " << i;
  }
  octomap_rt::box_query_t bq{};
  address(bq, 3);
  bq.boxes = {o.x() - 6.0, o.y() - 6.0, o.z() - 2.0, o.x() + 6.0, o.y() + 6.0, o.z() + 2.0};
  bq.num_values = 6;
  lc.publish(ort::protocol::kQueryBoxesChannel, &bq);
  const auto br = replies.wait_for<octomap_rt::box_reply_t>(3);
  ASSERT_EQ(br.status, Reply::REPLY_OK) << br.error;
  const auto c = query::count_box(reference, query::key_box(reference, &bq.boxes[0], &bq.boxes[3]));
  EXPECT_EQ(br.occupied[0], c.occupied);
  EXPECT_EQ(br.free[0], c.free);
  EXPECT_EQ(br.unknown[0], c.unknown);
  EXPECT_GT(server.residency_stats().restores, restores) << "the queries brought evicted regions back";
}

TEST(MemoryBound, ScansQueriesSavesAndRestartsPastTheBoundKeepOctomapsMap) {
  const ScanSet& set = real_scans();
  ASSERT_GE(set.scans.size(), 3u);
  const std::string dir = temp_dir("memory-bound");
  auto cfg = bounded_config(dir, 0);
  const auto one_pass = octomap_map(set, cfg, 1);
  auto reference = std::make_unique<octomap::OcTree>(*one_pass);
  for (const PosedScan& s : set.scans)
    reference->insertPointCloud(world_points(s), sensor_origin(s), cfg.engine.max_range, false, false);
  const uint64_t bound = tight_bound(*one_pass);
  cfg.max_map_memory = bound;
  lcm::LCM lc("memq://");
  {
    std::ostringstream log;
    daemon::MappingServer server(cfg, lc, log);
    Replies replies(server);
    server.start();
    int64_t sent = 0;
    uint64_t most = 0;
    send_pass(lc, server, set, sent, most);
    expect_queries_answer_as_octomap(lc, server, replies, set, *one_pass);
    send_pass(lc, server, set, sent, most);
    const daemon::MapResidencyStats st = server.residency_stats();
    EXPECT_LE(most, bound) << "the tree's memory after every scan (OctoMap's memoryUsage)";
    EXPECT_GT(st.evictions, 5u);
    EXPECT_GT(st.evicted_regions, 0u);
    EXPECT_EQ(st.max_bytes, bound);
    // What the bound cost, in the status message (octomap-rt status shows it).
    const octomap_rt::server_status_t msg = server.status();
    EXPECT_EQ(msg.map_memory_bound, static_cast<int64_t>(bound));
    EXPECT_GE(msg.region_evictions, static_cast<int64_t>(st.evictions));
    EXPECT_GT(msg.evicted_bytes, 0);
    EXPECT_LE(msg.memory_bytes, static_cast<int64_t>(bound + bound / 10)) << "resident, as the bound counts it";
    EXPECT_GT(msg.evict_passes, 0);
    EXPECT_GT(msg.evict_ms_max, 0);
    EXPECT_GE(msg.evict_ms, msg.evict_ms_max);
    EXPECT_GE(msg.evict_ms, msg.evict_count_ms);
    EXPECT_GT(msg.restore_ms_max, 0);
    EXPECT_GE(msg.restore_ms, msg.restore_ms_max);
    expect_octomaps(*server.whole_map(), *reference, "the whole map (a snapshot's copy)");
    ASSERT_TRUE(server.stop());
    expect_counts_balance(server.producer_stats());
  }
  // The saved file is the whole map, evicted regions included.
  {
    std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(dir + "/map.ot"));
    ASSERT_NE(read, nullptr);
    expect_octomaps(*dynamic_cast<octomap::OcTree*>(read.get()), *reference, "the saved map");
  }
  // A restart: the saved map comes back whole and goes down to the bound at once.
  {
    std::ostringstream log;
    daemon::MappingServer server(cfg, lc, log);
    // Loaded within the bound: the regions past it went from the file straight to the store,
    // the tree was never whole (nothing had to be evicted after the load).
    const daemon::MapResidencyStats st = server.residency_stats();
    EXPECT_GT(st.evicted_regions, 0u) << log.str();
    EXPECT_EQ(st.evictions, 0u) << "the whole map was built, then evicted: " << log.str();
    EXPECT_LE(server.with_map([](const octomap::OcTree& t) { return t.memoryUsage(); }), bound);
    expect_octomaps(*server.whole_map(), *reference, "after a restart");
  }
  // The saved map as the --prior of a new map: loaded within the bound too (split like the
  // map file, never built whole).
  {
    auto from_prior = cfg;
    from_prior.prior_path = dir + "/map.ot";
    from_prior.map_path = dir + "/from-prior.ot";
    std::ostringstream log;
    daemon::MappingServer server(from_prior, lc, log);
    const daemon::MapResidencyStats st = server.residency_stats();
    EXPECT_GT(st.evicted_regions, 0u) << log.str();
    EXPECT_EQ(st.evictions, 0u) << "the prior was built whole, then evicted: " << log.str();
    EXPECT_LE(server.with_map([](const octomap::OcTree& t) { return t.memoryUsage(); }), bound);
    expect_octomaps(*server.whole_map(), *reference, "a new map from the prior");
  }
}

// kill -9 while regions are evicted: the restart has the map as last saved (OctoMap's map
// of the scans its applied order lists), nothing of it lost to the store.
TEST(MemoryBound, KillDuringEvictionKeepsTheSavedMap) {
  const ScanSet& set = real_scans();
  ASSERT_GE(set.scans.size(), 3u);
  const std::string dir = temp_dir("memory-bound-kill");
  auto cfg = bounded_config(dir, 0);
  cfg.max_map_memory = tight_bound(*octomap_map(set, cfg, 1));
  cfg.save_interval_s = 0.05;
  const size_t n = set.scans.size();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    daemon::MappingServer server(cfg, lc, log);
    server.start();
    int64_t sent = 0;
    for (size_t k = 0; k < n; ++k) {
      const auto msg = scan_message(set.scans[k], "alpha", sent);
      lc.publish(kChannel, &msg);
      if (!wait_until_done(server, ++sent)) ::_exit(2);
    }
    // Wait for a save holding every scan of the first pass (its identity file says how many:
    // the order file may hold scans applied after the save's copy), then go on and die mid-pass.
    const auto deadline = SteadyClock::now() + std::chrono::seconds(60);
    while (SteadyClock::now() < deadline) {
      try {
        const auto saved = daemon::read_map_identity(cfg.map_path);
        if (saved && saved->order_entries >= n) break;
      } catch (const std::exception&) {}
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (server.residency_stats().evicted_regions == 0) ::_exit(3);
    for (size_t k = 0; k < 2; ++k) {
      const auto msg = scan_message(set.scans[k], "alpha", sent);
      lc.publish(kChannel, &msg);
      if (!wait_until_done(server, ++sent)) ::_exit(2);
    }
    ::kill(::getpid(), SIGKILL);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child exit " << WEXITSTATUS(status);
  lcm::LCM lc("memq://");
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  const auto order = server.applied_order();
  ASSERT_GE(order.size(), n);
  ScanSet ordered;
  for (const auto& e : order) ordered.scans.push_back(set.scans[size_t(e.seq) % n]);
  expect_octomaps(*server.whole_map(), *octomap_reference(ordered, cfg.engine.resolution, cfg.engine.max_range),
                  "after kill -9 and a restart");
  EXPECT_GT(server.residency_stats().evicted_regions, 0u);
}

// Decay sweeps over a map with evicted regions leave them in the store: each owes the steps
// (applied when a scan brings it back, or a copy is taken), and the map is the rule's map of
// OctoMap's scans (octree/decay.h, checked against OctoMap's own tree in forgetting_test).
TEST(MemoryBound, DecayOverEvictedRegionsIsTheRulesMap) {
  const ScanSet& set = real_scans();
  ASSERT_GE(set.scans.size(), 3u);
  const std::string dir = temp_dir("memory-bound-decay");
  auto cfg = bounded_config(dir, 0);
  cfg.max_map_memory = tight_bound(*octomap_map(set, cfg, 1));
  cfg.upkeep.decay_half_life_s = 10;
  cfg.upkeep.decay_step_s = 5;
  cfg.upkeep.manual = true;
  cfg.upkeep.slice_nodes = 20000;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  octomap::OcTree reference(cfg.engine.resolution);
  const DecayRule step{decay_factor(5, 10), cfg.upkeep.decay_delete_below};
  int64_t sent = 0;
  for (const PosedScan& s : set.scans) {
    const auto msg = scan_message(s, "alpha", sent);
    lc.publish(kChannel, &msg);
    ASSERT_TRUE(wait_until_done(server, ++sent));
    reference.insertPointCloud(world_points(s), sensor_origin(s), cfg.engine.max_range, false, false);
    server.upkeep()->decay_steps(1);
    decay_tree(reference, region_grid(cfg.upkeep.region_depth), step);
  }
  const daemon::MapResidencyStats st = server.residency_stats();
  EXPECT_GT(st.evictions, 0u);
  EXPECT_GT(st.restores, 0u) << "scans brought evicted regions back";
  EXPECT_GT(st.steps_owed, 0u) << "the sweeps left evicted regions in the store";
  const auto whole = server.whole_map();
  expect_octomaps(*whole, reference, "decayed with evicted regions");
  EXPECT_EQ(compare_structure(*whole, reference), "");
  server.stop();
}

TEST(MemoryBound, FlagsThatCannotWorkAreRefusedWithTheirReason) {
  auto cfg = test_config(0.1, true);
  cfg.max_map_memory = 64u << 20;
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("needs --map"), std::string::npos);
  cfg.map_path = "/tmp/x.ot";
  EXPECT_EQ(daemon::memory_bound_problem(cfg), "");
  cfg.max_map_memory = 1000;
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("1 MiB"), std::string::npos);
  cfg.max_map_memory = 64u << 20;
  cfg.region_store_max_bytes = 0;
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("--region-store-max"), std::string::npos);
  cfg.region_store_max_bytes = 1u << 30;
  cfg.evict_depth = cfg.upkeep.region_depth - 1;  // coarser than the sweeps' regions
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("--evict-depth"), std::string::npos);
  cfg.evict_depth = 0;
  EXPECT_EQ(daemon::evict_region_depth(cfg), cfg.upkeep.region_depth + 1);
  cfg.working_set_s = std::nan("");
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("--working-set-seconds"), std::string::npos);
  cfg.working_set_s = -1;
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("--working-set-seconds"), std::string::npos);
  cfg.working_set_s = 30;
  EXPECT_EQ(daemon::memory_bound_problem(cfg), "");
  cfg.queries.grid.rate_hz = 1;
  EXPECT_NE(daemon::memory_bound_problem(cfg).find("--grid-rate"), std::string::npos);
}

}  // namespace
}  // namespace ort::test
