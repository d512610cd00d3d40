// The query service with the read replica behind the map of record (91fca85, issue 23): each
// client keeps the newest map state it was answered from, so a client that read the map of
// record at N does not keep the replica (older than N) from the other clients' turns while
// stage 2 holds the map, and is itself never answered from a state older than N. The service
// runs on a MapState of the test's own: the test plays stage 2 (its changes, under the map
// lock) and stops the replica, so that it stays behind without its lock being held. Either
// order of the two clients' queries works: a turn that finds nothing free for the queries
// queued then asks again with those queued later (the turn never waits for the map of record).
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/intake/scan_queue.h"
#include "daemon/map/map_replica.h"
#include "daemon/queries/query_service.h"
#include "daemon/transport/lcm_loop.h"
#include "server/query_test_support.h"

namespace ort::test {
namespace {

// The replies on kReply, through the loop's own thread (memq://: only it may handle).
struct LoopReplies {
  std::mutex m;
  std::condition_variable cv;
  std::vector<Reply> got;
  explicit LoopReplies(daemon::LcmLoop& loop) {
    loop.subscribe(kReply, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
      Reply r;
      if (r.decode(rb.data, 0, static_cast<int>(rb.data_size)) < 0) return;
      std::lock_guard lock(m);
      got.push_back(r);
      cv.notify_all();
    });
  }
  // The reply to `request_id` within `timeout_ms`, if any.
  std::optional<Reply> wait_for(int64_t request_id, int timeout_ms) {
    std::unique_lock lock(m);
    std::optional<Reply> out;
    cv.wait_for(lock, std::chrono::milliseconds(timeout_ms), [&] {
      for (const Reply& r : got)
        if (r.request_id == request_id) out = r;
      return out.has_value();
    });
    return out;
  }
};

// A change to the map of record as stage 2 makes one: under the exclusive lock, counted, and
// handed to the replica.
void change_map(daemon::MapState& map, const octomap::point3d& p) {
  std::unique_lock lock(map.mutex);
  daemon::MapStep step = [p](octomap::OcTree& t) { t.updateNode(p, true); };
  step(*map.tree);
  map.version++;
  map.replica->step_applied(step, map);
}

// The replica stopped at state 4 (its lock free) and the map of record at 5, both holding the
// voxel at p occupied, with the query service running on them.
class QueryReplicaTest : public ::testing::Test {
 protected:
  const octomap::point3d p{1.05f, 0.05f, 0.05f};
  lcm::LCM lc{"memq://"};
  daemon::MapState map;
  std::unique_ptr<daemon::MapReplica> replica;
  daemon::ScanQueue scans{1 << 20, 1 << 24};
  std::unique_ptr<daemon::LcmLoop> loop;
  std::unique_ptr<LoopReplies> replies;
  std::unique_ptr<daemon::QueryService> service;

  void SetUp() override {
    map.tree = std::make_unique<octomap::OcTree>(0.1);
    replica = std::make_unique<daemon::MapReplica>(map, OctreeUpdateOptions{}, uint64_t{64} << 20);
    map.replica = replica.get();
    for (int k = 0; k < 4; ++k) change_map(map, p);
    ASSERT_TRUE(replica->wait_for(4, 20));
    ASSERT_TRUE(replica->caught_up());
    replica->stop();
    change_map(map, p);
    ASSERT_EQ(map.version, 5u);
    ASSERT_EQ(replica->state().version, 4u);
    ASSERT_FALSE(replica->caught_up());
    loop = std::make_unique<daemon::LcmLoop>(lc, Log{});
    replies = std::make_unique<LoopReplies>(*loop);
    service =
        std::make_unique<daemon::QueryService>(daemon::QueryServiceConfig{}, map, scans, *loop, "test-server", 0.1);
    service->open();
    loop->start();
    service->start();
  }
  void TearDown() override {
    if (service) service->stop();
    if (loop) loop->stop();
    map.replica = nullptr;
  }
  void ask(int64_t id, const std::string& client) {
    auto q = point_query(id, {p.x(), p.y(), p.z()}, client);
    lc.publish(ort::protocol::kQueryChannel, &q);
  }
  // Client "a" answered from the map of record (free) at 5.
  void a_reads_the_map_of_record() {
    ask(1, "a");
    const auto a1 = replies->wait_for(1, 20000);
    ASSERT_TRUE(a1.has_value());
    ASSERT_EQ(a1->status, Reply::REPLY_OK) << a1->error;
    ASSERT_EQ(a1->snapshot_id, 5);
  }
  // b's reply, answered from the replica at 4 while the test held the map of record.
  static void expect_from_the_replica(const std::optional<Reply>& b) {
    ASSERT_TRUE(b.has_value()) << "b waited for the map of record: a's newer state kept the replica from it";
    EXPECT_EQ(b->status, Reply::REPLY_OK) << b->error;
    EXPECT_EQ(b->snapshot_id, 4);
    ASSERT_EQ(b->num_results, 1);
    EXPECT_EQ(b->occupancy[0], Reply::OCC_OCCUPIED);
  }
  // a's reply once the map of record is free again: never older than the 5 it saw.
  void expect_a_after_release(int64_t request_id) {
    const auto a2 = replies->wait_for(request_id, 20000);
    ASSERT_TRUE(a2.has_value()) << "a's query was lost";
    EXPECT_EQ(a2->status, Reply::REPLY_OK) << a2->error;
    EXPECT_GE(a2->snapshot_id, 5) << "a was answered from an older state than before";
  }
};

TEST_F(QueryReplicaTest, AClientAnsweredFromTheMapOfRecordDoesNotKeepTheReplicaFromOthers) {
  ASSERT_NO_FATAL_FAILURE(a_reads_the_map_of_record());
  // Stage 2 holds the map of record: "b" (answered from nothing yet) is answered from the
  // replica at 4 meanwhile; "a" waits, because 4 is older than what it was answered from.
  std::unique_lock held(map.mutex);
  ask(2, "b");
  const auto b = replies->wait_for(2, 5000);
  ask(3, "a");
  const auto a_held = replies->wait_for(3, 300);
  held.unlock();
  expect_from_the_replica(b);
  EXPECT_FALSE(a_held.has_value()) << "a was answered from state " << a_held->snapshot_id << " after state 5";
  expect_a_after_release(3);
}

// The other order: a's query is the only one queued when the turn starts (it needs the map of
// record, which stage 2 holds); b's, arriving while a's waits, is answered from the replica
// all the same, and does not wait for the whole of stage 2's hold.
TEST_F(QueryReplicaTest, AQueryWaitingForTheMapOfRecordDoesNotHoldUpOneTheReplicaCanAnswer) {
  ASSERT_NO_FATAL_FAILURE(a_reads_the_map_of_record());
  std::unique_lock held(map.mutex);
  const int64_t deferred = service->service_stats().turns_deferred;
  ask(2, "a");
  // The turn found nothing to read for a alone (the map held, the replica older than 5).
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (service->service_stats().turns_deferred == deferred && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_GT(service->service_stats().turns_deferred, deferred) << "a's turn never found the map held";
  ask(3, "b");
  const auto b = replies->wait_for(3, 10000);
  const bool a_meanwhile = replies->wait_for(2, 0).has_value();
  held.unlock();
  expect_from_the_replica(b);
  EXPECT_FALSE(a_meanwhile) << "a was answered from the replica's state 4 after state 5";
  expect_a_after_release(2);
}

}  // namespace
}  // namespace ort::test
