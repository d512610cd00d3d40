#include "server/scan_fixtures.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "engine/map_engine.h"

namespace ort::test {

octomap_rt::scan_t scan_message(const PosedScan& scan, const std::string& robot_id, int64_t seq) {
  octomap_rt::scan_t m;
  m.utime = 1'700'000'000'000'000 + seq * 100'000;
  m.seq = seq;
  for (int i = 0; i < 3; ++i) m.sensor_position[i] = scan.pose.trans()(i);
  const octomath::Quaternion& q = scan.pose.rot();
  m.sensor_orientation[0] = q.u();
  m.sensor_orientation[1] = q.x();
  m.sensor_orientation[2] = q.y();
  m.sensor_orientation[3] = q.z();
  m.max_range = -1;
  m.points_frame = octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  for (size_t i = 0; i < scan.points.size(); ++i) {
    m.xyz.push_back(scan.points[i].x());
    m.xyz.push_back(scan.points[i].y());
    m.xyz.push_back(scan.points[i].z());
  }
  m.num_xyz = static_cast<int32_t>(m.xyz.size());
  m.robot_id = robot_id;
  m.map_frame = "map";
  return m;
}

octomap_rt::scan_t small_scan(const std::string& robot_id, int64_t seq, int points) {
  PosedScan s;
  s.pose = octomap::pose6d(1.0f, 2.0f, 0.5f, 0.0, 0.0, 0.3);
  for (int i = 0; i < points; ++i) s.points.push_back(2.0f, 0.05f * static_cast<float>(i - points / 2), 0.1f);
  return scan_message(s, robot_id, seq);
}

octomap_rt::scan_t reaching_scan(int64_t seq, const octomap::point3d& at, double distance, int n) {
  std::mt19937 rng(static_cast<unsigned>(seq) + 11);
  std::normal_distribution<double> g(0.0, 1.0);
  PosedScan s;
  s.pose = octomap::pose6d(at.x(), at.y(), at.z(), 0.0, 0.0, 0.0);
  for (int i = 0; i < n; ++i) {
    const double d[3] = {g(rng), g(rng), g(rng)};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    s.points.push_back(float(d[0] / len * distance), float(d[1] / len * distance), float(d[2] / len * distance));
  }
  return scan_message(s, "alpha", seq);
}

std::vector<uint8_t> encode(const octomap_rt::scan_t& msg) {
  std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
  if (msg.encode(buf.data(), 0, static_cast<int>(buf.size())) < 0) ADD_FAILURE() << "encode failed";
  return buf;
}

void put_be32(std::vector<uint8_t>& buf, size_t offset, int32_t v) {
  const uint32_t u = static_cast<uint32_t>(v);
  buf[offset] = uint8_t(u >> 24);
  buf[offset + 1] = uint8_t(u >> 16);
  buf[offset + 2] = uint8_t(u >> 8);
  buf[offset + 3] = uint8_t(u);
}

daemon::ServerConfig test_config(double res, bool pipelined) {
  daemon::ServerConfig c;
  c.engine.resolution = res;
  c.engine.backend.kind = BackendKind::kCpu;
  c.pipeline = pipelined;
  c.save_interval_s = 0;
  c.status.period_s = 0.2;
  c.server_id = "test-server";
  // Tests that publish bursts on a busy machine must not lose scans to the overload policy
  // or the drain deadline; the tests of those policies set them.
  c.latency_bound_s = 0;
  c.drain_timeout_s = 600;
  // The same for the bounds by predicted stage time (--max-scan-time and the shared class's
  // budget): they judge a scan by how long scans took, so under a sanitizer or on a loaded
  // machine they refuse scans a test counts on (CI's TSan run: 2 of 5 refused as "predicted
  // too slow"). The tests of those bounds set them (producer_share_test, shared_budget_server_test).
  c.scan_costs.max_scan_stage_s = 0;
  c.scan_costs.shared.enabled = false;
  // A warm-up scan at every start would add up over the many servers the tests start; the
  // tests of the warm-up turn it on.
  c.warm_up_points = 0;
  return c;
}

bool wait_until_done(daemon::MappingServer& server, int64_t messages, std::chrono::seconds timeout) {
  const auto deadline = SteadyClock::now() + timeout;
  while (SteadyClock::now() < deadline) {
    int64_t received = 0, in_flight = 0;
    for (const auto& p : server.producer_stats()) {
      received += p.received;
      in_flight += p.in_flight;
    }
    if (received >= messages && in_flight == 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

void expect_counts_balance(const std::vector<daemon::ProducerStats>& stats) {
  for (const auto& p : stats) {
    EXPECT_EQ(p.in_flight, 0) << p.channel;
    EXPECT_EQ(p.received, p.applied + p.rejected + p.dropped) << p.channel;
    int64_t by_reason = 0;
    for (int64_t n : p.rejects) by_reason += n;
    EXPECT_EQ(by_reason, p.rejected) << p.channel;
  }
}

std::unique_ptr<octomap::OcTree> engine_reference(
    const daemon::ServerConfig& cfg, const std::vector<daemon::AppliedEntry>& order,
    const std::function<const PosedScan&(const std::string&, int64_t)>& by_robot_seq) {
  MapEngine engine(cfg.engine);
  auto tree = engine.make_tree();
  for (const auto& e : order) {
    const PosedScan& s = by_robot_seq(e.robot_id, e.seq);
    const octomap::Pointcloud world = world_points(s);
    ShotScan shot;
    engine.insert(sensor_origin(s), std::span<const octomap::point3d>(world.size() ? &world[0] : nullptr, world.size()),
                  *tree, shot);
  }
  return tree;
}

std::string temp_dir(const std::string& tag) {
  const auto dir = std::filesystem::temp_directory_path() / ("octomap-rt-" + tag + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

MapHold::MapHold(daemon::MappingServer& server) {
  holder_ = std::thread([this, &server] {
    server.with_map([this](const octomap::OcTree&) {
      std::unique_lock lock(m_);
      holding_ = true;
      cv_.notify_all();
      cv_.wait(lock, [this] { return release_; });
      return 0;
    });
  });
  std::unique_lock lock(m_);
  cv_.wait(lock, [this] { return holding_; });
}

void MapHold::release() {
  {
    std::lock_guard lock(m_);
    release_ = true;
  }
  cv_.notify_all();
  if (holder_.joinable()) holder_.join();
}

}  // namespace ort::test
