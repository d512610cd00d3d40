// What one query may cost (issue 21): a ray or box query past its work or time bound under
// the map lock is cut, its reply saying where and why, and the rays and boxes it did answer
// equal the query core's; a region or grid past its bound is refused; stopping the server
// cuts the query under the lock instead of waiting for it.
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "daemon/queries/query_clients.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "octomap_rt/region_chunk_t.hpp"
#include "protocol/channels.h"
#include "query/box_count.h"
#include "query/leaf_walk.h"
#include "query/ray_query.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

namespace wire = ort::protocol;

// As many rays as a query may have (2000), each through unknown space as far as the wire
// allows: without a bound one such query holds the read lock for tens of seconds.
octomap_rt::ray_query_t far_rays(int64_t id, int n) {
  octomap_rt::ray_query_t q{};
  address(q, id);
  q.ignore_unknown = 1;
  q.max_range = 10000;
  for (int i = 0; i < n; ++i) {
    q.origin_xyz.insert(q.origin_xyz.end(), {0.05f, 0.05f, 0.25f});
    q.direction_xyz.insert(q.direction_xyz.end(), {1.f, 0.001f * i, 0.3f});
  }
  q.num_xyz = static_cast<int32_t>(q.origin_xyz.size());
  return q;
}

void map_walls(daemon::MappingServer& server, lcm::LCM& lc, int scans) {
  for (int64_t k = 0; k < scans; ++k) {
    const auto s = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  }
  ASSERT_TRUE(wait_until_done(server, scans));
}

TEST(QueryBounds, RaysThroughUnknownSpaceAreCutAndTheReplySaysWhere) {
  QueryServer fixture;
  auto& [lc, log, server, replies] = fixture;
  map_walls(server, lc, 2);
  const auto q = far_rays(1, 2000);
  const auto t0 = SteadyClock::now();
  lc.publish(wire::kQueryRaysChannel, &q);
  const auto r = replies.wait_for<octomap_rt::ray_reply_t>(1);
  const double took = seconds_since(t0);
  ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
  EXPECT_NE(r.cut, Reply::CUT_NONE);
  EXPECT_GT(r.num_rays, 0);
  EXPECT_LT(r.num_rays, 2000);
  EXPECT_EQ(r.cut_at, r.num_rays);
  EXPECT_NE(r.error.find("cut at ray " + std::to_string(r.num_rays) + " of 2000"), std::string::npos) << r.error;
  EXPECT_LT(took, 3.0) << "the query held the map for " << took << " s";
  // The rays it answered are castRay's on the map.
  server.with_map([&](const octomap::OcTree& t) {
    query::RayBatchOptions opt;
    opt.ignore_unknown = true, opt.max_range = 10000;
    for (int i = 0; i < r.num_rays; ++i) {
      const auto a =
          query::cast_ray(t, octomap::point3d(0.05f, 0.05f, 0.25f), octomap::point3d(1.f, 0.001f * i, 0.3f), opt);
      EXPECT_EQ(r.hit[i], a.hit) << i;
      EXPECT_EQ(r.end_xyz[3 * i], a.end.x()) << i;
    }
    return 0;
  });
  server.stop();
  int64_t cut = 0;
  for (const auto& c : server.query_stats()) cut += c.cut;
  EXPECT_EQ(cut, 1);
}

// The time bound never cuts a query before its first ray (each ray is within the work bound):
// with a time bound already past when the turn starts (a turn that lost the core on a loaded
// machine), the reply answers ray 0 and says it was cut by time at 1, so a client that resends
// the rest always progresses. Before, such a reply answered none (CI's loaded ASan run).
TEST(QueryBounds, TheTimeBoundAnswersTheFirstRayAtLeast) {
  auto cfg = test_config(0.1, true);
  cfg.queries.bounds.lock_ms = 1e-9;
  QueryServer fixture(cfg);
  auto& [lc, log, server, replies] = fixture;
  map_walls(server, lc, 2);
  const auto q = far_rays(1, 3);
  lc.publish(wire::kQueryRaysChannel, &q);
  const auto r = replies.wait_for<octomap_rt::ray_reply_t>(1);
  ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
  EXPECT_EQ(r.cut, Reply::CUT_TIME);
  EXPECT_EQ(r.num_rays, 1);
  EXPECT_EQ(r.cut_at, 1);
  EXPECT_NE(r.error.find("--query-lock-ms"), std::string::npos) << r.error;
  server.stop();
}

TEST(QueryBounds, ARayLongerThanTheWorkBoundIsRefusedWithTheReason) {
  auto cfg = test_config(0.1, true);
  cfg.queries.bounds.max_work = 1000;
  QueryServer fixture(cfg);
  auto& [lc, log, server, replies] = fixture;
  const auto q = far_rays(1, 3);
  lc.publish(wire::kQueryRaysChannel, &q);
  const auto r = replies.wait_for<octomap_rt::ray_reply_t>(1);
  EXPECT_EQ(r.status, Reply::REPLY_BAD_REQUEST);
  EXPECT_NE(r.error.find("--query-max-work"), std::string::npos) << r.error;
  server.stop();
}

// The nodes a box walk visits: what a box query is charged.
int64_t nodes_in(const octomap::OcTree& t, const query::KeyBox& b) {
  int64_t n = 0;
  query::for_each_node_in(t, b, 0, [&](const octomap::OcTreeNode&, const query::NodeCube&, int64_t) {
    ++n;
    return true;
  });
  return n;
}

TEST(QueryBounds, WholeMapBoxesAreCutAtTheWorkBoundAndAnsweredOnesAreExact) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  // Set below once the map is known: 2.5 whole-map boxes' worth of node visits.
  daemon::MappingServer probe(test_config(0.1, true), lc, std::cerr);
  probe.start();
  map_walls(probe, lc, 3);
  const double all_lo[3] = {-1000, -1000, -1000}, all_hi[3] = {1000, 1000, 1000};
  const int64_t per_box =
      probe.with_map([&](const octomap::OcTree& t) { return nodes_in(t, query::key_box(t, all_lo, all_hi)); });
  probe.stop();
  ASSERT_GT(per_box, 100);

  lcm::LCM lc2("memq://");
  cfg.queries.bounds.max_work = static_cast<uint64_t>(per_box * 5 / 2);
  daemon::MappingServer server(cfg, lc2, std::cerr);
  Replies replies(server);
  server.start();
  map_walls(server, lc2, 3);
  octomap_rt::box_query_t bq{};
  address(bq, 7);
  for (int i = 0; i < 10; ++i) bq.boxes.insert(bq.boxes.end(), {-1000, -1000, -1000, 1000, 1000, 1000});
  bq.num_values = static_cast<int32_t>(bq.boxes.size());
  lc2.publish(wire::kQueryBoxesChannel, &bq);
  const auto br = replies.wait_for<octomap_rt::box_reply_t>(7);
  ASSERT_EQ(br.status, Reply::REPLY_OK) << br.error;
  EXPECT_EQ(br.cut, Reply::CUT_WORK);
  EXPECT_EQ(br.cut_at, 2);
  ASSERT_EQ(br.num_boxes, 2);
  EXPECT_NE(br.error.find("cut at box 2 of 10"), std::string::npos) << br.error;
  server.with_map([&](const octomap::OcTree& t) {
    const auto c = query::count_box(t, query::key_box(t, all_lo, all_hi));
    for (int b = 0; b < 2; ++b) {
      EXPECT_EQ(br.occupied[b], c.occupied);
      EXPECT_EQ(br.free[b], c.free);
      EXPECT_EQ(br.unknown[b], c.unknown);
    }
    return 0;
  });
  // A region of the whole map walks the same nodes: past the bound it is refused whole.
  octomap_rt::box_query_t region{};
  address(region, 8);
  cfg.queries.bounds.max_work = 10;
  region.mode = octomap_rt::box_query_t::MODE_REGION;
  region.include_free = 1;
  region.boxes = {-1000, -1000, -1000, 1000, 1000, 1000};
  region.num_values = 6;
  server.stop();

  lcm::LCM lc3("memq://");
  daemon::MappingServer small(cfg, lc3, std::cerr);
  Replies small_replies(small);
  small.start();
  map_walls(small, lc3, 3);
  lc3.publish(wire::kQueryBoxesChannel, &region);
  const auto rr = small_replies.wait_for<octomap_rt::region_chunk_t>(8);
  EXPECT_EQ(rr.status, Reply::REPLY_BAD_REQUEST);
  EXPECT_NE(rr.error.find("--query-max-work"), std::string::npos) << rr.error;
  small.stop();
}

TEST(QueryBounds, StoppingCutsTheQueryUnderTheLockWithinTheDrainBound) {
  auto cfg = test_config(0.1, true);
  cfg.queries.bounds.max_work = uint64_t{1} << 40;  // only the stop can end it early
  cfg.queries.bounds.lock_ms = 10000;
  cfg.drain_timeout_s = 1;
  QueryServer fixture(cfg);
  auto& [lc, log, server, replies] = fixture;
  map_walls(server, lc, 2);
  const auto q = far_rays(1, 2000);
  lc.publish(wire::kQueryRaysChannel, &q);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the query is under the lock now
  const auto t0 = SteadyClock::now();
  server.stop();
  const double took = seconds_since(t0);
  EXPECT_LT(took, 3.0) << "stop waited " << took << " s for the query";
  int64_t cut = 0;
  std::string why;
  for (const auto& c : server.query_stats()) cut += c.cut, why += c.last_error;
  EXPECT_EQ(cut, 1);
  EXPECT_NE(why.find("the server is stopping"), std::string::npos) << why;
}

TEST(QueryBounds, AMapTooWideForOneGridGetsTheGridAroundTheRobotSayingSo) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.grid.rate_hz = 20;
  cfg.queries.grid.z_min = 0, cfg.queries.grid.z_max = 1;
  cfg.queries.bounds.max_reply_bytes = 1u << 20;  // a grid of at most 1 M cells
  daemon::MappingServer server(cfg, lc, std::cerr);
  std::mutex m;
  std::vector<octomap_rt::grid_t> grids;
  server.lcm_loop().subscribe(wire::kGridChannel, [&](const lcm::ReceiveBuffer& rb, const std::string&) {
    octomap_rt::grid_t g;
    if (g.decode(rb.data, 0, static_cast<int>(rb.data_size)) < 0) return;
    std::lock_guard lock(m);
    grids.push_back(std::move(g));
  });
  server.start();
  map_walls(server, lc, 1);
  // One scan reaching 250 m out on both sides: the map's extent is 5000 x 5000 cells, and
  // before, the grid was refused from then on.
  auto far = wall_scan(1);
  far.xyz = {250.f, 250.f, 0.5f, -250.f, -250.f, 0.5f};
  far.num_xyz = 6;
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &far);
  ASSERT_TRUE(wait_until_done(server, 2));
  std::optional<octomap_rt::grid_t> got;
  for (int k = 0; k < 500 && !got; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::lock_guard lock(m);
    for (const auto& g : grids)
      if (g.snapshot_id == 2) got = g;
  }
  server.stop();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->status, Reply::REPLY_OK) << got->error;
  EXPECT_NE(got->error.find("clipped"), std::string::npos) << got->error;
  EXPECT_LE(int64_t(got->width) * got->height, int64_t(1) << 20);
  EXPECT_GT(got->width, 500);
  // Centred on the robot (the origin): the wall at x = 3 m is in it.
  EXPECT_LT(got->origin_x, 0.0);
  EXPECT_GT(got->origin_x + got->width * got->cell_size, 3.0);
}

TEST(QueryBounds, AReplyChannelLongerThanLcmAllowsIsRefusedNotAnswered) {
  lcm::LCM lc("memq://");
  daemon::MappingServer server(test_config(0.1, true), lc, std::cerr);
  server.start();
  auto q = point_query(1, {0.f, 0.f, 0.f});
  q.reply_channel = std::string(64, 'R');  // LCM publishes on at most 63 characters
  lc.publish(wire::kQueryChannel, &q);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  server.stop();
  int64_t answered = 0, dropped = 0;
  std::string why;
  for (const auto& c : server.query_stats()) {
    answered += c.answered;
    if (c.client_id == "?") dropped += c.dropped, why = c.last_error;
  }
  EXPECT_EQ(answered, 0);
  EXPECT_EQ(dropped, 1);
  // Refused before decode (the reply channel's string is longer than the wire allows).
  EXPECT_NE(why.find("string length"), std::string::npos) << why;
}

TEST(QueryBounds, AnIdleClientGivesItsSlotToANewOneAndTheTotalsStay) {
  daemon::QueryClients clients(4, 3, /*idle_expiry_us=*/1'000'000);
  clients.received("a", "R", 0);
  clients.count("a", daemon::QueryClients::Count::kAnswered);
  clients.received("b", "R", 500'000);
  clients.received("c", "R", 2'000'000);
  // Full: "a" has been idle for 2.5 s (past the 1 s expiry), so "d" takes its slot.
  clients.received("d", "R", 2'500'000);
  std::map<std::string, daemon::QueryClientStats> by_id;
  for (const auto& c : clients.snapshot()) by_id[c.client_id] = c;
  EXPECT_TRUE(by_id.count("d"));
  EXPECT_FALSE(by_id.count("a"));
  EXPECT_FALSE(by_id.count("*"));
  ASSERT_TRUE(by_id.count("~"));
  EXPECT_EQ(by_id["~"].received, 1);
  EXPECT_EQ(by_id["~"].answered, 1);
  // "b" is idle too now, but "e" finds the oldest idle one gone: "b" goes next.
  clients.received("e", "R", 2'600'000);
  int64_t received = 0;
  for (const auto& c : clients.snapshot()) received += c.received;
  EXPECT_EQ(received, 5);
  EXPECT_EQ(clients.snapshot().size(), 4u);  // c, d, e and "~"
}

TEST(QueryBounds, ATurnOnAnOlderStateTakesOnlyTheClientsAnsweredFromNoNewerOne) {
  // A query turn on the read replica at state 3: "a" was answered from state 5 (the map of
  // record), so its query stays queued for a later turn; "b" (answered from 2) is served.
  daemon::QueryClients clients(4, 8);
  clients.received("a", "R", 0);
  clients.received("b", "R", 0);
  clients.answered_at("a", 5);
  clients.answered_at("a", 4);  // never goes back
  clients.answered_at("b", 2);
  daemon::PendingQuery qa, qb;
  qa.msg = octomap_rt::occupancy_query_t{};
  qb.msg = octomap_rt::occupancy_query_t{};
  ASSERT_TRUE(clients.push("a", std::move(qa)));
  ASSERT_TRUE(clients.push("b", std::move(qb)));
  EXPECT_EQ(clients.newest_answered("a"), 5u);
  EXPECT_EQ(clients.oldest_answered_queued(), 2u);
  ASSERT_TRUE(clients.pop(3).has_value());
  EXPECT_FALSE(clients.pop(3).has_value()) << "a's query was taken by a turn older than its last answer";
  EXPECT_EQ(clients.oldest_answered_queued(), 5u);
  EXPECT_TRUE(clients.pop(5).has_value());
  EXPECT_EQ(clients.queued(), 0u);
}

}  // namespace
}  // namespace ort::test
