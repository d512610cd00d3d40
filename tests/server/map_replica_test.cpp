// The read replica (daemon/map/map_replica.h), in one process over memq://: after scans,
// clear-boxes and a reset it equals the map of record byte for byte (.ot), and a reader that
// holds it for a long time does not stop the octree stage: scans go on being applied, and the
// replica catches up once the reader lets go (the scans that waited applied as one list);
// while stage 2 holds the map of record, queries are answered from the replica.
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/persistence/map_store.h"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/channels.h"
#include "scene/synthetic_scene.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

std::string map_bytes(daemon::MappingServer& s) {
  return s.with_map([](const octomap::OcTree& t) { return daemon::serialize_map(t); });
}
std::string replica_bytes(daemon::MappingServer& s) {
  return s.with_readable_map([](const octomap::OcTree& t) { return daemon::serialize_map(t); });
}

TEST(MapReplica, EqualsTheMapOfRecordAfterScansEditsAndAReset) {
  const ScanSet set = make_synthetic_rooms();
  QueryServer fixture(with_edits(test_config(0.1, true)));
  auto& [lc, log, server, replies] = fixture;
  auto edit = [&](int64_t id, int8_t op, double lo_x) {
    octomap_rt::map_edit_t e{};
    e.request_id = id, e.client_id = "op", e.reply_channel = kReply, e.op = op;
    const double lo[3] = {lo_x, 0.5, 0.2}, hi[3] = {lo_x + 2.3, 2.9, 1.7};
    std::copy(lo, lo + 3, e.box_min), std::copy(hi, hi + 3, e.box_max);
    sign(e);
    lc.publish(ort::protocol::kMapEditChannel, &e);
    EXPECT_EQ(replies.wait_for<octomap_rt::map_edit_ack_t>(id).status, Reply::REPLY_OK);
  };
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "rover", static_cast<int64_t>(k));
    lc.publish("OCTOMAP_RT_SCAN_ROVER", &msg);
  }
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size())));
  edit(1, octomap_rt::map_edit_t::OP_CLEAR_TO_FREE, 1.05);
  edit(2, octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN, 4.4);
  const std::string after_edits = map_bytes(server);
  EXPECT_GT(after_edits.size(), 10'000u);
  EXPECT_EQ(replica_bytes(server), after_edits) << "the replica differs from the map of record";
  edit(3, octomap_rt::map_edit_t::OP_RESET, 0);
  const auto again = scan_message(set.scans[0], "rover", static_cast<int64_t>(set.scans.size()));
  lc.publish("OCTOMAP_RT_SCAN_ROVER", &again);
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size()) + 1));
  EXPECT_EQ(replica_bytes(server), map_bytes(server));
  server.stop();
}

TEST(MapReplica, AReaderHoldingItDoesNotStopTheOctreeStage) {
  const ScanSet set = make_synthetic_rooms();
  MemqServer fixture(test_config(0.1, true));
  auto& [lc, log, server] = fixture;
  // A reader holds the replica (a copy of a huge map) until every scan was applied to the map
  // of record: they are, without waiting for it.
  std::atomic<bool> release{false};
  std::thread reader([&] { server.hold_replica_until(release); });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "rover", static_cast<int64_t>(k));
    lc.publish("OCTOMAP_RT_SCAN_ROVER", &msg);
  }
  const bool applied = wait_until_done(server, static_cast<int64_t>(set.scans.size()));
  const auto during = server.replica_stats();
  const auto status = server.status();
  release = true;
  reader.join();
  ASSERT_TRUE(applied) << "scans waited for the reader";
  ASSERT_TRUE(during.has_value());
  EXPECT_EQ(status.map_version, static_cast<int64_t>(set.scans.size()));
  EXPECT_EQ(during->version, 0u) << "the replica was held: it lags";
  EXPECT_GT(during->pending_items, 0u);
  EXPECT_EQ(replica_bytes(server), map_bytes(server)) << "caught up once the reader let go";
  // It caught up by applying the scans that waited together (one voxel list), and still
  // equals the map of record, which applied them one by one.
  const auto after = server.replica_stats();
  EXPECT_GT(after->largest_batch, 1u);
  EXPECT_LT(after->updates, set.scans.size());
  server.stop();
}

TEST(MapReplica, QueriesAreAnsweredFromItWhileAScanHoldsTheMap) {
  QueryServer fixture;
  auto& [lc, log, server, replies] = fixture;
  octomap_rt::scan_t last;
  for (int64_t k = 0; k < 4; ++k) {
    last = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &last);
  }
  ASSERT_TRUE(wait_until_done(server, 4));
  (void)replica_bytes(server);  // the replica caught up with the map of record
  // The map of record is held as a scan's update holds it (for 3 s at most): a query is
  // answered meanwhile, from the replica, at the state both hold, and a query that waits
  // for its robot's next scan (not applied yet) is not answered from either.
  std::atomic<bool> release{false};
  std::thread writer([&] { server.hold_map_until(release); });
  std::thread timer([&] {
    for (int i = 0; i < 300 && !release; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    release = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  auto q = point_query(1, last.xyz);
  lc.publish(ort::protocol::kQueryChannel, &q);
  auto later = point_query(2, last.xyz);
  later.wait_robot_id = "alpha", later.wait_seq = 4, later.wait_timeout_ms = 300;
  lc.publish(ort::protocol::kQueryChannel, &later);
  const Reply r = replies.wait_for<Reply>(1);
  const bool while_held = !release;
  const Reply nr = replies.wait_for<Reply>(2);
  release = true;
  writer.join();
  timer.join();
  EXPECT_TRUE(while_held) << "the query waited for the map of record";
  ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
  EXPECT_EQ(r.snapshot_id, 4);
  ASSERT_EQ(r.num_results, last.num_xyz / 3);
  for (int8_t o : r.occupancy) EXPECT_EQ(o, Reply::OCC_OCCUPIED);
  EXPECT_EQ(nr.status, Reply::REPLY_NOT_READY) << "seq 4 was never sent";
  server.stop();
}

}  // namespace
}  // namespace ort::test
