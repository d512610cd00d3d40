// The read replica (daemon/map/map_replica.h), in one process over memq://: after scans,
// clear-boxes and a reset it equals the map of record byte for byte (.ot), and a reader that
// holds it for a long time does not stop the octree stage: scans go on being applied, and the
// replica catches up once the reader lets go (the scans that waited applied as one list);
// while stage 2 holds the map of record, queries are answered from the replica; while stage 2
// waits for the replica's room it does not hold the map of record, and with rebuilds on it
// does not wait: the replica falls behind and rebuilds; whole-map readers hold
// versions of it (octree/versions/map_version.h) that it goes on past.
#include <future>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/map/map_mutex.h"
#include "daemon/map/map_replica.h"
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
// Every scan of `set` from robot "rover", seq 0, 1, ...
void publish_as_rover(lcm::LCM& lc, const ScanSet& set) {
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "rover", static_cast<int64_t>(k));
    lc.publish("OCTOMAP_RT_SCAN_ROVER", &msg);
  }
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
  publish_as_rover(lc, set);
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size())));
  // Whole-map readers' versions too (a version before the edits, so that the next ones are
  // made from it: edits do not list their keys).
  EXPECT_EQ(server.readable_version()->map->ot_bytes(), map_bytes(server));
  edit(1, octomap_rt::map_edit_t::OP_CLEAR_TO_FREE, 1.05);
  edit(2, octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN, 4.4);
  const std::string after_edits = map_bytes(server);
  EXPECT_GT(after_edits.size(), 10'000u);
  EXPECT_EQ(replica_bytes(server), after_edits) << "the replica differs from the map of record";
  EXPECT_EQ(server.readable_version()->map->ot_bytes(), after_edits);
  edit(3, octomap_rt::map_edit_t::OP_RESET, 0);
  const auto again = scan_message(set.scans[0], "rover", static_cast<int64_t>(set.scans.size()));
  lc.publish("OCTOMAP_RT_SCAN_ROVER", &again);
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size()) + 1));
  EXPECT_EQ(replica_bytes(server), map_bytes(server));
  EXPECT_EQ(server.readable_version()->map->ot_bytes(), map_bytes(server));
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
  publish_as_rover(lc, set);
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

TEST(MapReplica, WholeMapReadersHoldVersionsThatTheReplicaDoesNotWaitFor) {
  // What snapshots, saves and the viewer map read: a version of the replica at the map's state
  // (read your writes), OctoMap's .ot of the map of record byte for byte; held while the map
  // goes on, it stays what it was, and the replica applies every scan meanwhile.
  const ScanSet set = make_synthetic_rooms();
  ASSERT_GE(set.scans.size(), 4u);
  MemqServer fixture(test_config(0.1, true));
  auto& [lc, log, server] = fixture;
  const size_t half = set.scans.size() / 2;
  auto publish = [&](size_t from, size_t to) {
    for (size_t k = from; k < to; ++k) {
      const auto msg = scan_message(set.scans[k], "rover", static_cast<int64_t>(k));
      lc.publish("OCTOMAP_RT_SCAN_ROVER", &msg);
    }
  };
  publish(0, half);
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(half)));
  const auto held = server.readable_version();
  ASSERT_TRUE(held);
  const std::string held_bytes = held->map->ot_bytes();
  EXPECT_EQ(held_bytes, map_bytes(server));
  EXPECT_EQ(held->version, static_cast<uint64_t>(server.status().map_version));
  EXPECT_EQ(held->scans, half);
  publish(half, set.scans.size());
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size())));
  const std::string now = map_bytes(server);
  EXPECT_EQ(replica_bytes(server), now) << "the replica did not catch up while a version was held";
  EXPECT_EQ(held->map->ot_bytes(), held_bytes) << "a held version changed";
  EXPECT_NE(held_bytes, now);
  const auto newer = server.readable_version();
  EXPECT_EQ(newer->map->ot_bytes(), now);
  EXPECT_EQ(newer->version, static_cast<uint64_t>(server.status().map_version));
  EXPECT_EQ(newer->map->nodes(), server.with_map([](const octomap::OcTree& t) { return t.size(); }));
  const auto stats = server.replica_stats();
  EXPECT_GE(stats->versions_built, 2u);
  server.stop();
}

TEST(MapReplica, StageTwoWaitsForItsRoomWithoutHoldingTheMapOfRecord) {
  const ScanSet set = make_synthetic_rooms();
  ASSERT_GE(set.scans.size(), 4u);
  auto cfg = test_config(0.1, true);
  cfg.replica_pending_bytes = 1;        // a scan queued behind another has no room: stage 2 waits for it
  cfg.replica_rebuild_slice_nodes = 0;  // the rule without rebuilds (the default)
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  std::atomic<bool> release{false};
  std::thread reader([&] { server.hold_replica_until(release); });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  publish_as_rover(lc, set);
  // The map of record stops at the scans the replica's queue has room for; stage 2 waits. Wait
  // for the wait itself: a map version that stays put for a while is no sign of it on a loaded
  // machine, where stage 2 may just be slow (CI's ASan run read writer_waited_ms 0).
  const auto waits = [&] { return server.replica_stats().value_or(daemon::ReplicaStats{}).writer_waits; };
  for (int i = 0; i < 1000 && waits() == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_GT(waits(), 0u) << "stage 2 did not wait for the held replica";
  const int64_t version = server.status().map_version;
  ASSERT_LT(version, static_cast<int64_t>(set.scans.size())) << "stage 2 did not wait for the held replica";
  // Meanwhile the map of record can be read (stage 2 waits for room before it takes the lock).
  std::atomic<bool> read{false};
  std::thread other([&] {
    server.with_map([](const octomap::OcTree& t) { return t.size(); });
    read = true;
  });
  for (int i = 0; i < 200 && !read; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const bool read_while_waiting = read;
  release = true;
  reader.join();
  other.join();
  EXPECT_TRUE(read_while_waiting) << "stage 2 held the map of record while it waited for the replica";
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size())));
  EXPECT_EQ(replica_bytes(server), map_bytes(server));
  const auto stats = server.replica_stats();
  ASSERT_TRUE(stats.has_value());
  EXPECT_GT(stats->writer_waited_ms, 0);
  // (How long its thread waited depends on when it got to the lock: only that it waited is sure.)
  EXPECT_GT(stats->lock_wait_ms_max, 0) << "its thread waited for the reader";
  server.stop();
}

TEST(MapReplica, PastItsRoomItFallsBehindAndStageTwoGoesOn) {
  // Past the replica's room stage 2 does not wait: the replica falls behind (counted, with its
  // reason), drops its queue, and rebuilds from the map of record in slices once its thread is
  // free; meanwhile whole-map readers read the map of record; once caught up it equals it.
  const ScanSet set = make_synthetic_rooms();
  ASSERT_GE(set.scans.size(), 4u);
  auto cfg = test_config(0.1, true);
  cfg.replica_pending_bytes = 1;         // a scan queued behind another has no room
  cfg.replica_rebuild_slice_nodes = 64;  // a rebuild of many slices
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  std::atomic<bool> release{false};
  std::thread reader([&] { server.hold_replica_until(release); });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  publish_as_rover(lc, set);
  // Every scan is applied while the reader still holds the replica (no time is measured: the
  // map version counts them).
  const bool applied = wait_until_done(server, static_cast<int64_t>(set.scans.size()));
  const auto during = server.replica_stats().value_or(daemon::ReplicaStats{});
  // Whole-map readers read the map of record meanwhile (the replica holds an older state).
  const bool readers_read_the_record = applied && during.behind && replica_bytes(server) == map_bytes(server);
  release = true;
  reader.join();
  ASSERT_TRUE(applied) << "stage 2 waited for the held replica";
  EXPECT_TRUE(readers_read_the_record);
  EXPECT_GE(during.fell_behind, 1u);
  EXPECT_TRUE(during.behind);
  EXPECT_GE(during.dropped_items, 1u);
  EXPECT_NE(during.behind_reason.find("bound of 1 bytes"), std::string::npos) << during.behind_reason;
  EXPECT_LT(during.version, set.scans.size()) << "the replica was held: it lags";
  // After the release it rebuilds and catches up (the counted event: a rebuild done, its version).
  const auto caught_up = [&] {
    const auto st = server.replica_stats().value_or(daemon::ReplicaStats{});
    return st.rebuilds_done >= 1 && !st.behind && st.version == set.scans.size();
  };
  for (int i = 0; i < 2000 && !caught_up(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_TRUE(caught_up()) << "the replica never caught up";
  const auto after = server.replica_stats().value_or(daemon::ReplicaStats{});
  EXPECT_GT(after.rebuild_slices, 1u) << "one slice copied the whole map";
  EXPECT_GT(after.rebuild_regions_copied, 1u);
  // The replica itself (caught up: readers read it again), and a version made from it.
  EXPECT_EQ(replica_bytes(server), map_bytes(server));
  EXPECT_EQ(server.readable_version()->map->ot_bytes(), map_bytes(server));
  // It goes on from there as before: one more scan, applied to both.
  const auto again = scan_message(set.scans[0], "rover", static_cast<int64_t>(set.scans.size()));
  lc.publish("OCTOMAP_RT_SCAN_ROVER", &again);
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(set.scans.size()) + 1));
  EXPECT_EQ(replica_bytes(server), map_bytes(server));
  server.stop();
}

TEST(MapReplica, ItsLockLetsAWaitingWriterInBeforeNewReaders) {
  // The replica's lock (daemon/map/map_mutex.h): readers that keep overlapping never keep its
  // writer out, because a reader coming after a waiting writer waits too. The map of record's
  // lock keeps std::shared_mutex's reader preference.
  for (bool writers_first : {false, true}) {
    daemon::MapMutex m;
    if (writers_first) m.prefer_writers();
    m.lock_shared();
    std::atomic<bool> wrote{false};
    std::thread writer([&] {
      m.lock();
      wrote = true;
      m.unlock();
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the writer waits now (readers first: surely)
    // With writers first, a reader is refused once the writer waits: wait for that (bounded), not a time.
    bool second_reader = m.try_lock_shared();
    for (int i = 0; writers_first && second_reader && i < 2000; ++i) {
      m.unlock_shared();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      second_reader = m.try_lock_shared();
    }
    if (second_reader) m.unlock_shared();
    EXPECT_EQ(second_reader, !writers_first) << (writers_first ? "writers first" : "readers first");
    EXPECT_FALSE(wrote);
    m.unlock_shared();
    writer.join();
    EXPECT_TRUE(wrote);
  }
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

// What made the daemon's stop take 24-95 s in the hostile-mix bench: the replica's thread, at
// low priority, applied its whole backlog of big scans before it ended, and the final save
// waited for it. Now stop() leaves the backlog (the server stops the replica at its drain
// deadline and saves the map of record), and readers read the map of record from then on.
TEST(MapReplica, StopLeavesItsBacklogAndReadersReadTheMapOfRecord) {
  daemon::MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  daemon::MapReplica replica(map, OctreeUpdateOptions{}, uint64_t{1} << 32, /*max_batch_voxels=*/1000);
  map.replica = &replica;
  std::shared_lock reader(replica.state().mutex);  // a reader holds it: the backlog grows
  for (uint16_t k = 0; k < 50; ++k) {
    VoxelList voxels;
    for (uint16_t i = 0; i < 1000; ++i)
      voxels.push_back(VoxelUpdate{uint16_t(32768 + i), uint16_t(32768 + k), 32768, kStateOccupied});
    map.version++;
    map.scans++;
    map.newest_scan["rover"] = daemon::MapState::NewestScan{"rover", k, map.scans};
    replica.scan_applied(voxels, map, "rover");  // one batch each (1000 voxels)
  }
  auto stopped = std::async(std::launch::async, [&] { replica.stop(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  reader.unlock();
  ASSERT_EQ(stopped.wait_for(std::chrono::seconds(20)), std::future_status::ready);
  EXPECT_LE(replica.stats().updates, 1u) << "the replica applied its backlog before it stopped";
  EXPECT_LT(replica.state().version, map.version);
  EXPECT_TRUE(replica.stopped_behind());
  EXPECT_EQ(&daemon::readable_map(map), &map);
  EXPECT_EQ(replica.read_version(map.version), nullptr);
  map.replica = nullptr;
}

// The time bound on a batch (goal 1 of issue 23's session-7 list): with --replica-batch-ms the
// scans queued behind a reader are applied in updates of about that long each, not as one
// catch-up that holds the replica's lock for all of them (a query turn that needs the replica
// waits behind one such update at most). A bound far below one scan's time: one scan an update,
// each cut counted; no bound: one joined update. The same tree either way.
TEST(MapReplica, ATimeBoundCutsTheCatchUpIntoUpdatesOfAboutThatLong) {
  std::string trees[2];
  for (const bool bounded : {false, true}) {
    SCOPED_TRACE(bounded ? "1e-9 ms" : "no time bound");
    daemon::MapState map;
    map.tree = std::make_unique<octomap::OcTree>(0.1);
    daemon::MapReplica replica(map, OctreeUpdateOptions{}, uint64_t{1} << 32, daemon::MapReplica::kDefaultBatchVoxels,
                               0, std::nullopt, true, bounded ? 1e-9 : 0);
    map.replica = &replica;
    const int n = 50;
    {
      std::shared_lock reader(replica.state().mutex);  // a reader holds it: the backlog grows
      for (uint16_t k = 0; k < n; ++k) {
        VoxelList voxels;
        for (uint16_t i = 0; i < 1000; ++i)
          voxels.push_back(VoxelUpdate{uint16_t(32768 + i), uint16_t(32768 + k), 32768, kStateOccupied});
        map.version++;
        map.scans++;
        map.newest_scan["rover"] = daemon::MapState::NewestScan{"rover", k, map.scans};
        replica.scan_applied(voxels, map, "rover");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_TRUE(replica.wait_for(map.version, 20));
    const auto stats = replica.stats();
    EXPECT_EQ(stats.version, map.version);
    if (bounded) {
      EXPECT_EQ(stats.largest_batch, 1u);
      EXPECT_EQ(stats.updates, uint64_t(n));
      EXPECT_GE(stats.batches_cut_by_time, 1u) << "the cuts are not counted";
      EXPECT_GT(stats.ms_per_voxel, 0) << "no estimate of the update's time";
    } else {
      // The replica thread took what was queued when it first woke (one scan, or more on a slow
      // machine) and waits for the reader's lock with it; the rest queue behind it and are joined
      // into one update after it.
      EXPECT_LE(stats.updates, 3u) << "the backlog was not joined";
      EXPECT_GE(stats.scans_in_batches, uint64_t(n) - 2) << "the backlog was not joined";
      EXPECT_EQ(stats.batches_cut_by_time, 0u);
    }
    {
      std::shared_lock lock(replica.state().mutex);
      trees[bounded] = daemon::serialize_map(*replica.state().tree);
    }
    replica.stop();
    map.replica = nullptr;
  }
  EXPECT_TRUE(trees[0] == trees[1]) << "the cut catch-up made another tree";
}

}  // namespace
}  // namespace ort::test
