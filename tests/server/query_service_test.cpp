// The query service in one process over memq://: answers equal server/query/ on the
// server's map, read-your-writes, and bad queries (each refused with a reason or dropped, and
// counted) while mapping goes on. Edits: query_edits_test.cpp.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "protocol/channels.h"
#include "protocol/limits.h"
#include "query/box_count.h"
#include "query/point_query.h"
#include "query/projected_grid.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

TEST(QueryService, ReadYourWritesSeesTheScanJustSent) {
  QueryServer fixture;
  auto& [lc, log, server, replies] = fixture;
  for (int64_t k = 0; k < 6; ++k) {
    const octomap_rt::scan_t scan = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &scan);
    // Right after the scan: ask about its own end points, waiting for its seq.
    auto q = point_query(100 + k, scan.xyz);
    q.wait_seq = k, q.wait_robot_id = "alpha", q.wait_timeout_ms = 20000;
    lc.publish(ort::protocol::kQueryChannel, &q);
    const Reply r = replies.wait_for<Reply>(100 + k);
    ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
    EXPECT_GE(r.snapshot_id, k + 1);
    ASSERT_EQ(r.num_results, scan.num_xyz / 3);
    for (int8_t o : r.occupancy) ASSERT_EQ(o, Reply::OCC_OCCUPIED) << "scan " << k;
  }
  // Without waiting for a seq that never comes: NOT_READY after the timeout, counted.
  auto late = point_query(200, {0, 0, 0});
  late.wait_seq = 99, late.wait_robot_id = "alpha", late.wait_timeout_ms = 200;
  lc.publish(ort::protocol::kQueryChannel, &late);
  const Reply nr = replies.wait_for<Reply>(200);
  EXPECT_EQ(nr.status, Reply::REPLY_NOT_READY);
  EXPECT_NE(nr.error.find("wait_seq 99"), std::string::npos) << nr.error;
  server.stop();
  for (const auto& c : server.query_stats())
    if (c.client_id == "tester") {
      EXPECT_EQ(c.not_ready, 1);
    }
}

TEST(QueryService, AnEmptyWaitRobotIdMeansNoWaitWhateverWaitSeqHolds) {
  QueryServer fixture;
  auto& [lc, log, server, replies] = fixture;
  // A default-initialised query has wait_seq 0 and no robot: answered at once, no scan needed.
  auto plain = point_query(1, {3.05f, 0.f, 0.05f});
  plain.wait_seq = 0, plain.wait_robot_id = "", plain.wait_timeout_ms = 0;
  lc.publish(ort::protocol::kQueryChannel, &plain);
  const Reply r = replies.wait_for<Reply>(1);
  ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
  EXPECT_EQ(r.occupancy[0], Reply::OCC_UNKNOWN);
  // With the robot named, the same wait_seq 0 waits for that robot's scan 0.
  auto waiting = plain;
  waiting.request_id = 2, waiting.wait_robot_id = "alpha", waiting.wait_timeout_ms = 300;
  lc.publish(ort::protocol::kQueryChannel, &waiting);
  EXPECT_EQ(replies.wait_for<Reply>(2).status, Reply::REPLY_NOT_READY);
  const auto scan = wall_scan(0);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &scan);
  waiting.request_id = 3, waiting.wait_timeout_ms = 20000;
  lc.publish(ort::protocol::kQueryChannel, &waiting);
  const Reply seen = replies.wait_for<Reply>(3);
  ASSERT_EQ(seen.status, Reply::REPLY_OK) << seen.error;
  EXPECT_EQ(seen.occupancy[0], Reply::OCC_OCCUPIED);
  server.stop();
}

TEST(QueryService, AnswersEqualTheQueryCoreOnTheServersMap) {
  QueryServer fixture;
  auto& [lc, log, server, replies] = fixture;
  for (int64_t k = 0; k < 3; ++k) {
    const auto s = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  }
  ASSERT_TRUE(wait_until_done(server, 3));
  std::vector<float> pts;
  for (int i = 0; i < 300; ++i) pts.insert(pts.end(), {-1.f + 0.023f * i, -1.2f + 0.0087f * i, 0.31f});
  auto pq = point_query(1, pts);
  pq.depth = 14;
  lc.publish(ort::protocol::kQueryChannel, &pq);
  const Reply pr = replies.wait_for<Reply>(1);
  ASSERT_EQ(pr.status, Reply::REPLY_OK) << pr.error;
  server.with_map([&](const octomap::OcTree& t) {
    const auto want = query::query_points(t, pts, 14);
    for (size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(pr.occupancy[i], int8_t(want[i].state));
      EXPECT_EQ(pr.probability[i], want[i].probability);
    }
    return 0;
  });

  octomap_rt::ray_query_t rq{};
  address(rq, 2);
  rq.max_range = 20;
  for (int i = 0; i < 50; ++i) {
    rq.origin_xyz.insert(rq.origin_xyz.end(), {0.05f, 0.05f, 0.25f});
    rq.direction_xyz.insert(rq.direction_xyz.end(), {1.f, -0.5f + 0.02f * i, 0.f});
  }
  rq.num_xyz = static_cast<int32_t>(rq.origin_xyz.size());
  lc.publish(ort::protocol::kQueryRaysChannel, &rq);
  const auto rr = replies.wait_for<octomap_rt::ray_reply_t>(2);
  ASSERT_EQ(rr.status, Reply::REPLY_OK) << rr.error;
  server.with_map([&](const octomap::OcTree& t) {
    for (int i = 0; i < 50; ++i) {
      octomap::point3d end;
      const bool hit = t.castRay(octomap::point3d(0.05f, 0.05f, 0.25f), octomap::point3d(1.f, -0.5f + 0.02f * i, 0.f),
                                 end, false, 20);
      EXPECT_EQ(rr.hit[i], hit);
      EXPECT_EQ(rr.end_xyz[3 * i], end.x());
    }
    return 0;
  });

  octomap_rt::box_query_t bq{};
  address(bq, 3);
  bq.boxes = {2.9, -1.0, 0.0, 3.3, 1.0, 1.0, -0.5, -0.5, 0.0, 0.5, 0.5, 0.5};
  bq.num_values = 12;
  lc.publish(ort::protocol::kQueryBoxesChannel, &bq);
  const auto br = replies.wait_for<octomap_rt::box_reply_t>(3);
  ASSERT_EQ(br.status, Reply::REPLY_OK) << br.error;
  server.with_map([&](const octomap::OcTree& t) {
    for (int b = 0; b < 2; ++b) {
      const auto c = query::count_box(t, query::key_box(t, &bq.boxes[6 * b], &bq.boxes[6 * b + 3]));
      EXPECT_EQ(br.occupied[b], c.occupied);
      EXPECT_EQ(br.free[b], c.free);
      EXPECT_EQ(br.unknown[b], c.unknown);
    }
    return 0;
  });
  EXPECT_GT(br.occupied[0], 0);

  octomap_rt::grid_query_t gq{};
  address(gq, 4);
  gq.z_min = 0.0, gq.z_max = 0.5, gq.cell_size = 0.2;
  lc.publish(ort::protocol::kQueryGridChannel, &gq);
  const auto g = replies.wait_for<octomap_rt::grid_t>(4);
  ASSERT_EQ(g.status, Reply::REPLY_OK) << g.error;
  server.with_map([&](const octomap::OcTree& t) {
    query::GridRequest req;
    req.z_min = 0, req.z_max = 0.5, req.cell_voxels = 2;
    const auto want = query::projected_grid(t, req);
    EXPECT_EQ(g.width, want.width);
    EXPECT_EQ(g.height, want.height);
    EXPECT_EQ(g.num_chunks, 1);
    int differing = 0;
    for (int i = 0; i < g.num_cells && i < int(want.cells.size()); ++i)
      differing += g.cells[i] != int8_t(want.cells[i]);
    EXPECT_EQ(differing, 0);
    return 0;
  });
  server.stop();
}

TEST(QueryService, BadQueriesAreRefusedOrDroppedAndCounted) {
  auto cfg = test_config(0.1, true);
  cfg.queries.per_client_queue = 2;
  QueryServer fixture(cfg);
  auto& [lc, log, server, replies] = fixture;
  auto nan = point_query(1, {0, NAN, 0});
  lc.publish(ort::protocol::kQueryChannel, &nan);
  EXPECT_EQ(replies.wait_for<Reply>(1).status, Reply::REPLY_BAD_REQUEST);
  auto deep = point_query(2, {0, 0, 0});
  deep.depth = 17;
  lc.publish(ort::protocol::kQueryChannel, &deep);
  EXPECT_NE(replies.wait_for<Reply>(2).error.find("depth"), std::string::npos);
  // Dropped (no trustworthy address): too many points, empty / over-long reply channel,
  // garbage, a huge count in the raw bytes.
  auto many = point_query(3, std::vector<float>(3 * (protocol::kMaxQueryPoints + 1), 0.f));
  lc.publish(ort::protocol::kQueryChannel, &many);
  auto empty = point_query(4, {0, 0, 0});
  empty.reply_channel = "";
  lc.publish(ort::protocol::kQueryChannel, &empty);
  auto longer = point_query(5, {0, 0, 0});
  longer.reply_channel = std::string(200, 'R');
  lc.publish(ort::protocol::kQueryChannel, &longer);
  auto reflect = point_query(6, {0, 0, 0});
  reflect.reply_channel = "OCTOMAP_RT_SCAN_ALPHA";
  lc.publish(ort::protocol::kQueryChannel, &reflect);
  std::vector<uint8_t> raw(point_query(7, {0, 0, 0}).getEncodedSize());
  point_query(7, {0, 0, 0}).encode(raw.data(), 0, static_cast<int>(raw.size()));
  std::vector<uint8_t> huge = raw;
  huge[8 + 40] = 0x7f;  // num_xyz's high byte
  lc.publish(ort::protocol::kQueryChannel, huge.data(), static_cast<unsigned>(huge.size()));
  lc.publish(ort::protocol::kQueryChannel, raw.data(), 20);
  // Edits without a server token are refused.
  octomap_rt::map_edit_t e{};
  e.request_id = 8, e.client_id = "op", e.reply_channel = kReply, e.op = 3;
  sign(e);
  lc.publish(ort::protocol::kMapEditChannel, &e);
  EXPECT_NE(replies.wait_for<octomap_rt::map_edit_ack_t>(8).error.find("--control-token"), std::string::npos);
  // A flood from one client: its queue holds 2, the rest are BUSY; another client is served.
  for (int i = 0; i < 200; ++i) {
    auto q = point_query(1000 + i, std::vector<float>(3 * 5000, 0.5f), "flooder");
    lc.publish(ort::protocol::kQueryChannel, &q);
  }
  auto calm = point_query(9, {0, 0, 0}, "calm");
  lc.publish(ort::protocol::kQueryChannel, &calm);
  EXPECT_EQ(replies.wait_for<Reply>(9).status, Reply::REPLY_OK);
  // ... and mapping goes on.
  const auto s = wall_scan(0);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  ASSERT_TRUE(wait_until_done(server, 1));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  server.stop();
  std::map<std::string, daemon::QueryClientStats> by;
  for (const auto& c : server.query_stats()) by[c.client_id] = c;
  EXPECT_EQ(by["tester"].bad, 2);
  EXPECT_EQ(by["?"].dropped, 6);
  EXPECT_EQ(by["op"].edits_refused, 1);
  EXPECT_GT(by["flooder"].busy, 0);
  EXPECT_EQ(by["flooder"].busy + by["flooder"].answered, 200);
  EXPECT_EQ(by["calm"].answered, 1);
}

}  // namespace
}  // namespace ort::test
