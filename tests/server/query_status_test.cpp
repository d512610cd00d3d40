// What the query service reports and publishes besides answers, in one process over memq://:
// the per-client counters and refusal reasons in server_status_t, and the 2D grid published
// on OCTOMAP_RT_GRID at --grid-rate (off by default).
#include <map>
#include <thread>

#include <gtest/gtest.h>

#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"
#include "query/projected_grid.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using Status = octomap_rt::server_status_t;

// The status as a subscriber decodes it (the message must encode and decode whole).
Status round_trip(const Status& s) {
  std::vector<uint8_t> buf(s.getEncodedSize());
  EXPECT_EQ(s.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  Status out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return out;
}

TEST(QueryStatus, CountsEachClientsQueriesAndWhyTheyWereRefused) {
  auto cfg = test_config(0.1, true);
  cfg.queries.per_client_queue = 2;
  QueryServer fixture(cfg);
  auto& [lc, log, server, replies] = fixture;
  for (int i = 0; i < 3; ++i) {
    auto ok = point_query(1 + i, {0, 0, 0});
    lc.publish(ort::protocol::kQueryChannel, &ok);
    ASSERT_EQ(replies.wait_for<Reply>(1 + i).status, Reply::REPLY_OK);
  }
  for (int depth : {17, 20}) {  // one reason, two numbers
    auto deep = point_query(10 + depth, {0, 0, 0});
    deep.depth = depth;
    lc.publish(ort::protocol::kQueryChannel, &deep);
    ASSERT_EQ(replies.wait_for<Reply>(10 + depth).status, Reply::REPLY_BAD_REQUEST);
  }
  auto late = point_query(40, {0, 0, 0});
  late.wait_robot_id = "alpha", late.wait_seq = 5, late.wait_timeout_ms = 50;
  lc.publish(ort::protocol::kQueryChannel, &late);
  ASSERT_EQ(replies.wait_for<Reply>(40).status, Reply::REPLY_NOT_READY);
  auto nowhere = point_query(41, {0, 0, 0});
  nowhere.reply_channel = "";
  lc.publish(ort::protocol::kQueryChannel, &nowhere);
  for (int i = 0; i < 100; ++i) {  // its queue holds 2: the rest are BUSY
    auto q = point_query(1000 + i, std::vector<float>(3 * 5000, 0.5f), "flooder");
    lc.publish(ort::protocol::kQueryChannel, &q);
  }
  octomap_rt::map_edit_t e{};
  e.request_id = 50, e.client_id = "op", e.reply_channel = kReply, e.op = 3;
  lc.publish(ort::protocol::kMapEditChannel, &e);
  ASSERT_EQ(replies.wait_for<octomap_rt::map_edit_ack_t>(50).status, Reply::REPLY_REFUSED);
  auto flood_done = [&] {
    for (const auto& c : server.query_stats())
      if (c.client_id == "flooder") return c.answered + c.busy == 100;
    return false;
  };
  for (int i = 0; i < 2000 && !flood_done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  auto last = point_query(2000, {0, 0, 0}, "flooder");  // heard from after the others
  lc.publish(ort::protocol::kQueryChannel, &last);
  ASSERT_EQ(replies.wait_for<Reply>(2000).status, Reply::REPLY_OK);

  const Status s = round_trip(server.status());
  EXPECT_EQ(s.queries_received, 3 + 2 + 1 + 100 + 1 + 1);
  EXPECT_EQ(s.queries_bad, 2);
  EXPECT_EQ(s.queries_not_ready, 1);
  EXPECT_EQ(s.queries_dropped, 1);
  EXPECT_EQ(s.edits_refused, 1);
  EXPECT_EQ(s.edits_applied, 0);
  EXPECT_GT(s.queries_busy, 0);
  // Every query with a usable address was answered, refused as bad, busy or not ready.
  EXPECT_EQ(s.queries_answered + s.queries_bad + s.queries_busy + s.queries_not_ready + s.edits_refused,
            s.queries_received);
  std::map<std::string, int64_t> reasons;
  ASSERT_EQ(s.num_query_refusal_reasons, static_cast<int32_t>(s.query_refusal_reason.size()));
  for (int i = 0; i < s.num_query_refusal_reasons; ++i) reasons[s.query_refusal_reason[i]] = s.query_refusal_count[i];
  EXPECT_EQ(reasons["depth # is not in #..#"], 2);
  EXPECT_EQ(reasons["busy: the client's queue is full (--query-queue)"], s.queries_busy);
  EXPECT_EQ(reasons["not ready: the awaited map state came after wait_timeout_ms"], 1);
  EXPECT_EQ(reasons["reply_channel must have #..# characters"], 1);
  EXPECT_EQ(reasons["map edits are off: the server was started without --control-token"], 1);

  std::map<std::string, octomap_rt::query_client_stats_t> by;
  ASSERT_EQ(s.num_query_clients, static_cast<int32_t>(s.query_clients.size()));
  for (const auto& c : s.query_clients) by[c.client_id] = c;
  ASSERT_EQ(by.count("tester"), 1u);
  EXPECT_EQ(by["tester"].answered, 3);
  EXPECT_EQ(by["tester"].bad, 2);
  EXPECT_EQ(by["tester"].not_ready, 1);
  EXPECT_EQ(by["tester"].reply_channel, kReply);
  EXPECT_NE(by["tester"].last_error.find("wait_seq 5"), std::string::npos) << by["tester"].last_error;
  EXPECT_EQ(by["flooder"].busy + by["flooder"].answered, 101);
  EXPECT_EQ(by["flooder"].queue_depth, 0);
  EXPECT_GT(by["flooder"].last_utime, by["tester"].last_utime);
  EXPECT_EQ(by["?"].dropped, 1);
  EXPECT_EQ(by["op"].edits_refused, 1);
  server.stop();
}

// Collects the grid_t rows published on OCTOMAP_RT_GRID.
struct GridRows {
  std::mutex m;
  std::vector<octomap_rt::grid_t> got;
  explicit GridRows(daemon::MappingServer& s) {
    s.lcm_loop().subscribe(ort::protocol::kGridChannel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
      octomap_rt::grid_t g;
      if (g.decode(rb.data, 0, static_cast<int>(rb.data_size)) < 0) return;
      std::lock_guard lock(m);
      got.push_back(std::move(g));
    });
  }
  size_t count() {
    std::lock_guard lock(m);
    return got.size();
  }
};

TEST(QueryStatus, TheGridIsPublishedAtItsRateOnlyWhenAsked) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.grid.rate_hz = 20;
  cfg.queries.grid.z_min = 0, cfg.queries.grid.z_max = 0.5, cfg.queries.grid.cell_size = 0.2;
  daemon::MappingServer server(cfg, lc, std::cerr);
  GridRows rows(server);
  server.start();
  const auto scan = wall_scan(0);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &scan);
  ASSERT_TRUE(wait_until_done(server, 1));
  octomap_rt::grid_t latest{};
  for (int i = 0; i < 200 && latest.snapshot_id < 1; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::lock_guard lock(rows.m);
    for (const auto& g : rows.got)
      if (g.snapshot_id >= 1) latest = g;
  }
  ASSERT_EQ(latest.snapshot_id, 1) << "no grid of the map after scan 0";
  EXPECT_EQ(latest.request_id, -1);
  EXPECT_EQ(latest.status, Reply::REPLY_OK) << latest.error;
  EXPECT_EQ(latest.num_chunks, 1);
  server.with_map([&](const octomap::OcTree& t) {  // what a grid query gets, by the projected_map rule
    query::GridRequest req;
    req.z_min = 0, req.z_max = 0.5, req.cell_voxels = 2;
    const auto want = query::projected_grid(t, req);
    EXPECT_EQ(latest.width, want.width);
    EXPECT_EQ(latest.height, want.height);
    int differing = 0, occupied = 0;
    for (int i = 0; i < latest.num_cells && i < int(want.cells.size()); ++i) {
      differing += latest.cells[i] != int8_t(want.cells[i]);
      occupied += latest.cells[i] == Reply::OCC_OCCUPIED;
    }
    EXPECT_EQ(differing, 0);
    EXPECT_GT(occupied, 0);
    return 0;
  });
  // At its rate: the map did not change, the grid keeps coming (for late subscribers).
  const size_t before = rows.count();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_GE(rows.count(), before + 4);
  EXPECT_GE(server.status().grids_published, 5);
  server.stop();

  lcm::LCM quiet_lc("memq://");
  daemon::MappingServer quiet(test_config(0.1, true), quiet_lc, std::cerr);  // no --grid-rate
  GridRows none(quiet);
  quiet.start();
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &scan);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(none.count(), 0u);
  EXPECT_EQ(quiet.status().grids_published, 0);
  quiet.stop();
}

}  // namespace
}  // namespace ort::test
