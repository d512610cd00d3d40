// Map edits through the query service in one process over memq://: applied in order with the
// scans only with the MAC of the server's token within the time window and once, a costly edit
// refused before it starts, every edit audited, acked and never shed or dropped.
#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "daemon/queries/edit_gate.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/channels.h"
#include "protocol/limits.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

TEST(QueryService, EditsNeedTheTokenAndApplyInOrderWithTheScans) {
  QueryServer fixture(with_edits(test_config(0.1, true)));
  auto& [lc, log, server, replies] = fixture;
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
  QueryServer fixture(with_edits(test_config(0.1, true)));
  auto& [lc, log, server, replies] = fixture;
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
  QueryServer fixture(with_edits(test_config(0.1, true)));
  auto& [lc, log, server, replies] = fixture;
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
  auto cfg = test_config(0.1, true);
  cfg.latency_bound_s = 1e-9;  // every queued scan is stale when stage 1 takes it
  QueryServer fixture(with_edits(cfg));
  auto& [lc, log, server, replies] = fixture;
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
  auto cfg = test_config(0.1, true);
  cfg.drain_timeout_s = 0;
  QueryServer fixture(with_edits(cfg));
  auto& [lc, log, server, replies] = fixture;
  MapHold hold(server);
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
  const auto until = SteadyClock::now() + std::chrono::seconds(20);
  while ((op_stats().received < kSent || scans_received() < kSent) && SteadyClock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::thread stopper([&] { server.stop(); });
  while (op_stats().edits_refused == 0 && SteadyClock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  hold.release();
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

}  // namespace
}  // namespace ort::test
