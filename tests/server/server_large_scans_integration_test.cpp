// 300 000-point scans (3.6 MB messages, ~2 600 UDP fragments each) from three producers at
// 5 Hz all arrive and are applied under the daemon's DEFAULT LCM URL (host-local udpm with
// recv_buf_size raised up to net.core.rmem_max). A lost fragment loses a whole scan, so this
// is what the raised receive buffer is for (../shared/notes/lcm-1.3.1.md §3.3).
#include <gtest/gtest.h>

#include <signal.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <thread>

#include "integration_harness.h"
#include "scene/scan_set.h"

namespace ort::test {
namespace {

constexpr int kProducers = 3;
constexpr size_t kPoints = 300000;
constexpr int kScansPerProducer = 10;  // 2 s of traffic at 5 Hz
constexpr double kRate = 5.0;

// Three poses, each with 300 000 points 1-3 m away in random directions: rays short enough
// that the daemon applies 30 of them in seconds even on the CPU back end.
ScanSet make_large_scans() {
  ScanSet set;
  set.name = "large synthetic";
  std::mt19937 rng(4242);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), range(1.0f, 3.0f);
  for (int s = 0; s < 3; ++s) {
    PosedScan scan;
    scan.pose = octomap::pose6d(2.0f * s, 0.5f * s, 1.0f, 0.0, 0.0, 0.3 * s);
    for (size_t i = 0; i < kPoints; ++i) {
      float x, y, z, n;
      do {
        x = u(rng), y = u(rng), z = u(rng);
        n = std::sqrt(x * x + y * y + z * z);
      } while (n < 1e-3f || n > 1.0f);
      const float r = range(rng) / n;
      scan.points.push_back(x * r, y * r, z * r);
    }
    set.scans.push_back(std::move(scan));
  }
  return set;
}

TEST(ServerLargeScansIntegration, ThreeProducersOf300kPointScansAt5HzLoseNothingUnderTheDefaultUrl) {
  NetworkNamespace ns("large");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("large");
  ::unsetenv("LCM_DEFAULT_URL");  // the point: the daemon's own default URL
  const std::string plain_default = "udpm://239.255.76.67:7667?ttl=0";
  std::printf("namespace: %s; net.core.rmem_max there: %lld bytes (read-only inside a namespace)\n", ns.how().c_str(),
              (long long)ns.rmem_max());

  const std::string graph = dir + "/large.graph";
  save_scan_graph(make_large_scans(), graph);

  // The test's own listener receives every scan datagram too (udpm is one group): give it
  // the largest buffer allowed, so the kernel's error count speaks about the daemon's socket.
  StatusWatcher status(plain_default + "&recv_buf_size=" + std::to_string(ns.rmem_max() > 0 ? ns.rmem_max() : 4194304));
  ASSERT_TRUE(status.good());
  ChildProcess server({server_program(), "-r", "0.2", "--map", dir + "/map.ot", "--save-interval", "0"},
                      dir + "/server.log");
  ASSERT_TRUE(status.wait_for([](const auto&) { return true; }, 60)) << "no status from the daemon\n" << server.log();
  const int64_t kernel_errors_before = status.latest()->kernel_rcvbuf_errors;

  std::vector<std::unique_ptr<ChildProcess>> producers;
  for (int i = 0; i < kProducers; ++i) {
    producers.push_back(std::make_unique<ChildProcess>(
        std::vector<std::string>{client_program(), "replay", graph, "--robot", "big" + std::to_string(i), "--first",
                                 std::to_string(i), "--count", "1", "--repeat", std::to_string(kScansPerProducer),
                                 "--rate", std::to_string(kRate)},
        dir + "/producer" + std::to_string(i) + ".log"));
    // Robots are not synchronised; start them a little apart as real ones would be.
    std::this_thread::sleep_for(std::chrono::milliseconds(67));
  }
  for (auto& p : producers) EXPECT_EQ(p->wait(120), 0) << p->log();

  const int64_t expected = kProducers * kScansPerProducer;
  // Wait until every producer's scans are accounted for; then look at the counts.
  const auto settled = status.wait_for(
      [&](const octomap_rt::server_status_t& s) {
        int64_t accounted = 0;
        for (const auto& r : s.robots) accounted += r.scans_applied + r.scans_rejected + r.scans_dropped;
        return s.robots.size() >= static_cast<size_t>(kProducers) && accounted >= expected && s.scan_queue_depth == 0 &&
               s.shot_queue_depth == 0;
      },
      300);
  std::optional<octomap_rt::server_status_t> last = settled ? settled : status.latest();
  ASSERT_TRUE(last);
  std::printf(
      "kernel UDP receive errors during the run (every socket in the namespace): %lld; drops on the "
      "daemon's own socket: %lld; scans applied %lld of %lld\n",
      (long long)(last->kernel_rcvbuf_errors - kernel_errors_before), (long long)last->socket_rcvbuf_drops,
      (long long)total_applied(*last), (long long)expected);
  for (int i = 0; i < kProducers; ++i) {
    const auto* r = find_robot_ci(*last, "big" + std::to_string(i));
    ASSERT_NE(r, nullptr) << "no scan of producer " << i << " arrived\n" << server.log();
    std::printf("  big%d: received %lld applied %lld rejected %lld dropped %lld missed %lld, %lld points\n", i,
                (long long)r->scans_received, (long long)r->scans_applied, (long long)r->scans_rejected,
                (long long)r->scans_dropped, (long long)r->scans_missed, (long long)r->points_applied);
    EXPECT_EQ(r->scans_received, kScansPerProducer);
    EXPECT_EQ(r->scans_applied, kScansPerProducer);
    EXPECT_EQ(r->scans_missed, 0);
    EXPECT_EQ(r->scans_rejected, 0);
    EXPECT_EQ(r->scans_dropped, 0);
    EXPECT_EQ(r->points_applied, static_cast<int64_t>(kScansPerProducer * kPoints));
  }
  EXPECT_LE(last->socket_rcvbuf_drops, 0) << "datagrams dropped on the daemon's socket (-1: not measurable)";
  ASSERT_TRUE(settled) << server.log();

  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(120), 0) << server.log();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
