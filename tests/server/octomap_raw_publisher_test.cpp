// The viewer publisher (serving/octomap_raw_publisher.h) over many periods: it copies the map
// only when the map changed, encodes each map version once, and with a read replica encodes
// from the replica without copying the map (a copy only to drop cells outside the occupancy
// band). What a viewer receives is OctoMap's own .bt of the map, after every change.
#include "daemon/serving/octomap_raw_publisher.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>

#include "daemon/map/map_identity.h"
#include "daemon/map/map_replica.h"
#include "libbot_copy/raw_t.hpp"

namespace ort::daemon {
namespace {

// Rays in a 12 m room from the origin, as a robot's scan would add them.
octomap::Pointcloud room_scan(unsigned seed, int rays = 1500) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-6.f, 6.f);
  octomap::Pointcloud cloud;
  for (int i = 0; i < rays; ++i) cloud.push_back(u(rng), u(rng), u(rng) / 4);
  return cloud;
}

std::string bt_of(const octomap::OcTree& tree) {
  octomap::OcTree copy(tree);  // writeBinary prunes the tree it is given
  std::ostringstream out;
  copy.writeBinary(out);
  return out.str();
}

// What a viewer on the channel received: the messages' count and the newest one's .bt bytes.
struct Viewer {
  std::mutex mutex;
  std::condition_variable got;
  int64_t messages = 0;
  std::string newest_bt;

  void receive(const lcm::ReceiveBuffer& rbuf) {
    libbot_copy::raw_t m;
    if (m.decode(rbuf.data, 0, static_cast<int>(rbuf.data_size)) < 0) return;
    std::lock_guard lock(mutex);
    ++messages;
    newest_bt.assign(m.data.begin(), m.data.end());
    got.notify_all();
  }
  // Waits for `more` messages after the ones seen so far, the last of them carrying `bt`.
  bool wait_for(int64_t more, const std::string& bt) {
    std::unique_lock lock(mutex);
    const int64_t target = messages + more;
    return got.wait_for(lock, std::chrono::seconds(20), [&] { return messages >= target && newest_bt == bt; });
  }
};

// One publisher at 200 Hz on a memq:// LCM over `map`; the test changes the map as a scan
// would (through apply_map_step, which also replays the change on the replica).
struct PublisherRun {
  explicit PublisherRun(MapState& map, OctomapRawConfig cfg = {}) : map_(map) {
    cfg.rate_hz = 200;
    cfg.max_bytes = 16u << 20;
    loop.subscribe(cfg.channel, [this](const lcm::ReceiveBuffer& rbuf, const std::string&) { viewer.receive(rbuf); });
    loop.start();
    publisher = std::make_unique<OctomapRawPublisher>(cfg, map, loop, Log());
    publisher->start();
  }
  ~PublisherRun() {
    publisher->stop();
    loop.stop();
  }
  void scan(const octomap::Pointcloud& cloud) {
    std::unique_lock lock(map_.mutex);
    // By value: the replica replays the step later, on its own thread.
    apply_map_step(map_, [cloud](octomap::OcTree& tree) { tree.insertPointCloud(cloud, octomap::point3d(0, 0, 0)); });
  }

  MapState& map_;
  lcm::LCM lcm{"memq://"};
  LcmLoop loop{lcm, Log()};
  Viewer viewer;
  std::unique_ptr<OctomapRawPublisher> publisher;
};

TEST(OctomapRawPublisher, CopiesTheMapOnlyWhenItChanged) {
  MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  octomap::OcTree reference(0.1);  // OctoMap on its own, the same scans
  map.tree->insertPointCloud(room_scan(1), octomap::point3d(0, 0, 0));
  reference.insertPointCloud(room_scan(1), octomap::point3d(0, 0, 0));
  PublisherRun run(map);
  ASSERT_TRUE(run.viewer.wait_for(20, bt_of(reference)));  // 20 periods of one map
  EXPECT_EQ(run.publisher->map_copies(), 1);
  EXPECT_EQ(run.publisher->encodings(), 1);
  run.scan(room_scan(2));
  reference.insertPointCloud(room_scan(2), octomap::point3d(0, 0, 0));
  ASSERT_TRUE(run.viewer.wait_for(20, bt_of(reference)));
  EXPECT_EQ(run.publisher->map_copies(), 2);
  EXPECT_EQ(run.publisher->encodings(), 2);
}

TEST(OctomapRawPublisher, EncodesFromTheReadReplicaWithoutACopy) {
  MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  octomap::OcTree reference(0.1);
  map.tree->insertPointCloud(room_scan(3), octomap::point3d(0, 0, 0));
  reference.insertPointCloud(room_scan(3), octomap::point3d(0, 0, 0));
  MapReplica replica(map, OctreeUpdateOptions{}, 64u << 20);
  map.replica = &replica;
  {
    PublisherRun run(map);
    ASSERT_TRUE(run.viewer.wait_for(20, bt_of(reference)));  // 20 periods of one map
    EXPECT_EQ(run.publisher->encodings(), 1);
    run.scan(room_scan(4));
    reference.insertPointCloud(room_scan(4), octomap::point3d(0, 0, 0));
    ASSERT_TRUE(run.viewer.wait_for(20, bt_of(reference)));
    EXPECT_EQ(run.publisher->map_copies(), 0);
    EXPECT_EQ(run.publisher->encodings(), 2);
  }
  // The occupancy band changes the tree it encodes: the tree made from the replica's version is
  // the publisher's own, so the band needs no copy under a lock either; one encoding a version.
  OctomapRawConfig band;
  band.occupancy_min_z = -0.5;
  PublisherRun run(map, band);
  {
    std::unique_lock wait(run.viewer.mutex);
    ASSERT_TRUE(run.viewer.got.wait_for(wait, std::chrono::seconds(20), [&] { return run.viewer.messages >= 20; }));
  }
  EXPECT_EQ(run.publisher->map_copies(), 0);
  EXPECT_EQ(run.publisher->encodings(), 1);
  run.publisher->stop();
  map.replica = nullptr;
}

}  // namespace
}  // namespace ort::daemon
