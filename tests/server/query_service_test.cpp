// The query service in one process over memq://: answers equal server/query/ on the
// server's map, read-your-writes, map edits through the pipeline with the control token, and
// bad queries (each refused with a reason or dropped, and counted) while mapping goes on.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/queries/edit_gate.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "octomap_rt/region_chunk_t.hpp"
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
  lcm::LCM lc("memq://");
  daemon::MappingServer server(test_config(0.1, true), lc, std::cerr);
  Replies replies(server);
  server.start();
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
  lcm::LCM lc("memq://");
  daemon::MappingServer server(test_config(0.1, true), lc, std::cerr);
  Replies replies(server);
  server.start();
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
  lcm::LCM lc("memq://");
  daemon::MappingServer server(test_config(0.1, true), lc, std::cerr);
  Replies replies(server);
  server.start();
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

TEST(QueryService, EditsNeedTheTokenAndApplyInOrderWithTheScans) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.control_token = kToken;
  daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
  const auto s = wall_scan(0);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  octomap_rt::map_edit_t e{};
  e.request_id = 1, e.client_id = "op", e.reply_channel = kReply;
  e.op = octomap_rt::map_edit_t::OP_CLEAR_TO_FREE;
  e.flags = octomap_rt::map_edit_t::FLAG_INCLUDE_UNKNOWN;  // the box's unknown space too
  double lo[3] = {2.5, -2, 0}, hi[3] = {3.5, 2, 1};
  std::copy(lo, lo + 3, e.box_min), std::copy(hi, hi + 3, e.box_max);
  sign(e, "the wrong token, long enough");
  lc.publish(ort::protocol::kMapEditChannel, &e);
  EXPECT_EQ(replies.wait_for<octomap_rt::map_edit_ack_t>(1).status, Reply::REPLY_REFUSED);
  e.request_id = 2;
  sign(e);
  lc.publish(ort::protocol::kMapEditChannel, &e);  // queued behind the scan: the wall is cleared
  const auto ack = replies.wait_for<octomap_rt::map_edit_ack_t>(2);
  ASSERT_EQ(ack.status, Reply::REPLY_OK) << ack.error;
  EXPECT_EQ(ack.snapshot_id, 2);  // one scan, then the edit
  octomap_rt::box_query_t bq{};
  address(bq, 3);
  bq.min_snapshot_id = ack.snapshot_id;
  bq.boxes = {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]};
  bq.num_values = 6;
  lc.publish(ort::protocol::kQueryBoxesChannel, &bq);
  const auto br = replies.wait_for<octomap_rt::box_reply_t>(3);
  ASSERT_EQ(br.status, Reply::REPLY_OK);
  EXPECT_EQ(br.occupied[0], 0);
  EXPECT_EQ(br.unknown[0], 0);
  e.request_id = 4, e.op = octomap_rt::map_edit_t::OP_RESET;
  sign(e);
  lc.publish(ort::protocol::kMapEditChannel, &e);
  EXPECT_EQ(replies.wait_for<octomap_rt::map_edit_ack_t>(4).snapshot_id, 3);
  EXPECT_EQ(server.with_map([](const octomap::OcTree& t) { return t.size(); }), 0u);
  server.stop();
}

// An edit is applied only with the MAC of the server's token, within the time window, once:
// a forged, a tampered, a replayed and a stale edit are refused with their reasons and
// counted, and the token is in the bytes of none of them.
TEST(QueryService, EditsAreAuthenticatedByTheirMacWithinTheWindowAndOnce) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.control_token = kToken;
  daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
  octomap_rt::map_edit_t good{};
  good.request_id = 1, good.client_id = "op", good.reply_channel = kReply;
  good.op = octomap_rt::map_edit_t::OP_RESET;
  sign(good);
  std::vector<uint8_t> bytes(good.getEncodedSize());
  good.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_EQ(std::search(bytes.begin(), bytes.end(), kToken.begin(), kToken.end()), bytes.end());
  lc.publish(ort::protocol::kMapEditChannel, bytes.data(), static_cast<unsigned>(bytes.size()));
  const auto ok = replies.wait_for<octomap_rt::map_edit_ack_t>(1);
  ASSERT_EQ(ok.status, Reply::REPLY_OK) << ok.error;
  // Replayed: the same bytes again, as anyone who saw them could send.
  lc.publish(ort::protocol::kMapEditChannel, bytes.data(), static_cast<unsigned>(bytes.size()));
  auto forged = good;
  forged.request_id = 2;
  sign(forged, "a guess at the token, long enough");
  lc.publish(ort::protocol::kMapEditChannel, &forged);
  auto tampered = good;
  tampered.request_id = 3;
  sign(tampered);
  tampered.op = octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN;  // changed after signing
  lc.publish(ort::protocol::kMapEditChannel, &tampered);
  auto stale = good;
  stale.request_id = 4;
  sign(stale);
  stale.utime -= 120'000'000;  // two minutes old (the window is 30 s), signed as such
  protocol::sign_edit(stale, kToken, ort::protocol::kMapEditChannel);
  lc.publish(ort::protocol::kMapEditChannel, &stale);
  std::map<int64_t, std::string> why = {{2, "bad MAC"}, {3, "bad MAC"}, {4, "stale"}};
  for (const auto& [id, reason] : why) {
    const auto a = replies.wait_for<octomap_rt::map_edit_ack_t>(id);
    EXPECT_EQ(a.status, Reply::REPLY_REFUSED) << id;
    EXPECT_NE(a.error.find(reason), std::string::npos) << id << ": " << a.error;
  }
  // The replay was answered before the later edits (one LCM thread, in order): its ack has id 1.
  std::vector<std::string> acks_of_1;
  {
    std::lock_guard lock(replies.m);
    for (const auto& b : replies.got) {
      octomap_rt::map_edit_ack_t a;
      if (a.decode(b.data(), 0, static_cast<int>(b.size())) >= 0 && a.request_id == 1)
        acks_of_1.push_back(a.status == Reply::REPLY_OK ? "OK" : a.error);
    }
  }
  ASSERT_EQ(acks_of_1.size(), 2u);
  EXPECT_EQ(acks_of_1[0], "OK");
  EXPECT_NE(acks_of_1[1].find("replayed"), std::string::npos) << acks_of_1[1];
  server.stop();
  for (const auto& c : server.query_stats())
    if (c.client_id == "op") {
      EXPECT_EQ(c.received, 5);
      EXPECT_EQ(c.edits_applied, 1);
      EXPECT_EQ(c.edits_refused, 4);
    }
}

// The nonces of admitted edits are remembered while their utime is within the window, at most
// max_nonces of them; past that, edits are refused as too many until old ones expire.
TEST(EditGate, TheNonceCacheIsBoundedAndForgetsWithTheWindow) {
  daemon::EditGate gate({kToken, 1'000'000, 3});
  const int64_t t0 = now_utime();
  auto edit_at = [&](int64_t utime, int64_t nonce) {
    octomap_rt::map_edit_t e{};
    e.utime = utime, e.nonce = nonce, e.op = 3, e.client_id = "op", e.reply_channel = kReply;
    protocol::sign_edit(e, kToken, ort::protocol::kMapEditChannel);
    return e;
  };
  for (int64_t n = 0; n < 3; ++n)
    EXPECT_TRUE(gate.admit(edit_at(t0, n), ort::protocol::kMapEditChannel, t0).admitted());
  EXPECT_EQ(gate.admit(edit_at(t0, 0), ort::protocol::kMapEditChannel, t0).refusal, daemon::EditGateRefusal::kReplayed);
  EXPECT_EQ(gate.admit(edit_at(t0, 9), ort::protocol::kMapEditChannel, t0).refusal, daemon::EditGateRefusal::kTooMany);
  EXPECT_EQ(gate.remembered(), 3u);
  // 1.5 s later the first three are out of the window: forgotten, and a new edit is admitted.
  const int64_t t1 = t0 + 1'500'000;
  EXPECT_EQ(gate.admit(edit_at(t0, 9), ort::protocol::kMapEditChannel, t1).refusal, daemon::EditGateRefusal::kStale);
  EXPECT_TRUE(gate.admit(edit_at(t1, 9), ort::protocol::kMapEditChannel, t1).admitted());
  EXPECT_EQ(gate.remembered(), 1u);
  EXPECT_EQ(gate.admit(edit_at(t1 + 5'000'000, 10), ort::protocol::kMapEditChannel, t1).refusal,
            daemon::EditGateRefusal::kStale);  // from the future too
  daemon::EditGate off({"", 1'000'000, 3});
  EXPECT_EQ(off.admit(edit_at(t0, 1), ort::protocol::kMapEditChannel, t0).refusal, daemon::EditGateRefusal::kEditsOff);
}

// An edit whose cost passes its bound is refused before it starts, with the reason, and the
// map is untouched: marking the unknown space of a huge misaligned box free would build ~10^10
// nodes under the exclusive lock. The same box on known space only is applied (the map's
// nodes), and every edit leaves an audit line in the server's log.
TEST(QueryService, ACostlyEditIsRefusedBeforeItStartsAndEveryEditIsAudited) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.control_token = kToken;
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  Replies replies(server);
  server.start();
  const auto s = wall_scan(0);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  ASSERT_TRUE(wait_until_done(server, 1));
  const auto nodes = server.with_map([](const octomap::OcTree& t) { return t.size(); });
  octomap_rt::map_edit_t e{};
  e.request_id = 1, e.client_id = "op", e.reply_channel = kReply;
  e.op = octomap_rt::map_edit_t::OP_CLEAR_TO_FREE;
  e.flags = octomap_rt::map_edit_t::FLAG_INCLUDE_UNKNOWN;
  double lo[3] = {-3000.01, -3000.01, -3000.01}, hi[3] = {3000.01, 3000.01, 3000.01};
  std::copy(lo, lo + 3, e.box_min), std::copy(hi, hi + 3, e.box_max);
  sign(e);
  lc.publish(ort::protocol::kMapEditChannel, &e);
  const auto refused = replies.wait_for<octomap_rt::map_edit_ack_t>(1);
  EXPECT_EQ(refused.status, Reply::REPLY_REFUSED);
  EXPECT_NE(refused.error.find("too costly"), std::string::npos) << refused.error;
  EXPECT_EQ(server.with_map([](const octomap::OcTree& t) { return t.size(); }), nodes);
  e.request_id = 2, e.flags = 0;  // known space only: the wall and the free space before it
  sign(e);
  lc.publish(ort::protocol::kMapEditChannel, &e);
  const auto applied = replies.wait_for<octomap_rt::map_edit_ack_t>(2);
  ASSERT_EQ(applied.status, Reply::REPLY_OK) << applied.error;
  server.with_map([&](const octomap::OcTree& t) {
    for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it)
      EXPECT_EQ(it->getLogOdds(), t.getClampingThresMinLog());
    return 0;
  });
  server.stop();
  const std::string text = log.str();
  EXPECT_NE(text.find("map edit 1 from client 'op' (reply " + kReply +
                      "): clear-box to free (unknown voxels too) [-3000.01, -3000.01, -3000.01]..[3000.01, 3000.01, "
                      "3000.01] m: refused (REFUSED): too costly"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("map edit 2 from client 'op' (reply " + kReply + "): clear-box to free (known voxels only)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find(": applied, map state 2"), std::string::npos) << text;
}

// An edit is never shed for its age: with a latency bound every queued scan passes, the
// scans are dropped and counted to their producer, the edit is applied and acked, and no
// producer counts it.
TEST(QueryService, EditsAreNeverShedAsStale) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.control_token = kToken;
  cfg.latency_bound_s = 1e-9;  // every queued scan is stale when stage 1 takes it
  daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
  for (int64_t k = 0; k < 3; ++k) {
    const auto s = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  }
  octomap_rt::map_edit_t e{};
  e.request_id = 1, e.client_id = "op", e.reply_channel = kReply;
  e.op = octomap_rt::map_edit_t::OP_RESET;
  sign(e);
  lc.publish(ort::protocol::kMapEditChannel, &e);
  const auto ack = replies.wait_for<octomap_rt::map_edit_ack_t>(1);
  EXPECT_EQ(ack.status, Reply::REPLY_OK) << ack.error;
  ASSERT_TRUE(wait_until_done(server, 3));
  server.stop();
  int64_t dropped = 0;
  for (const auto& p : server.producer_stats()) dropped += p.dropped;
  EXPECT_EQ(dropped, 3);
  for (const auto& c : server.query_stats())
    if (c.client_id == "op") {
      EXPECT_EQ(c.edits_applied, 1);
    }
}

// Edits still queued when the drain deadline passes are refused and acked (not counted as a
// producer's scans): for the edit client, received = applied + refused. The test holds the
// map (stage 2 waits) so that edits are still queued when the server stops.
TEST(QueryService, EditsLeftAtShutdownAreRefusedNotDropped) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.control_token = kToken;
  cfg.drain_timeout_s = 0;
  daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
  std::mutex m;
  std::condition_variable cv;
  bool holding = false, release = false;
  std::thread holder([&] {
    server.with_map([&](const octomap::OcTree&) {
      std::unique_lock lock(m);
      holding = true;
      cv.notify_all();
      cv.wait(lock, [&] { return release; });
      return 0;
    });
  });
  {
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return holding; });
  }
  octomap_rt::map_edit_t e{};
  e.client_id = "op", e.reply_channel = kReply;
  e.op = octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN;
  double lo[3] = {2.5, -2, 0}, hi[3] = {3.5, 2, 1};
  std::copy(lo, lo + 3, e.box_min), std::copy(hi, hi + 3, e.box_max);
  constexpr int kSent = 20;
  for (int64_t k = 0; k < kSent; ++k) {
    const auto s = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
    e.request_id = 100 + k;
    sign(e);
    lc.publish(ort::protocol::kMapEditChannel, &e);
  }
  auto op_stats = [&] {
    for (const auto& c : server.query_stats())
      if (c.client_id == "op") return c;
    return daemon::QueryClientStats{};
  };
  auto scans_received = [&] {
    int64_t n = 0;
    for (const auto& p : server.producer_stats()) n += p.received;
    return n;
  };
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((op_stats().received < kSent || scans_received() < kSent) && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::thread stopper([&] { server.stop(); });
  while (op_stats().edits_refused == 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  {
    std::lock_guard lock(m);
    release = true;
  }
  cv.notify_all();
  holder.join();
  stopper.join();
  int64_t scans = 0, dropped = 0;
  for (const auto& p : server.producer_stats()) scans += p.applied + p.dropped + p.rejected, dropped += p.dropped;
  EXPECT_EQ(scans, kSent);
  EXPECT_GT(dropped, 0);
  const auto op = op_stats();
  EXPECT_EQ(op.received, kSent);
  EXPECT_GT(op.edits_refused, 0);
  EXPECT_EQ(op.edits_applied + op.edits_refused, op.received);
  EXPECT_NE(op.last_error.find("stopped before applying it"), std::string::npos) << op.last_error;
}

TEST(QueryService, BadQueriesAreRefusedOrDroppedAndCounted) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.queries.per_client_queue = 2;
  daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
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
