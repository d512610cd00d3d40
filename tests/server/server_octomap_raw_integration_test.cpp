// octomap-rt-server --octomap-raw-rate: a real server in a network namespace publishes the
// map on OCTOMAP; a receiver with the kernel's default UDP buffer (as Java's LCM and most
// viewers have) gets it, decodes it with a type generated from the viewers' field list, and
// OcTree::readBinary on its data gives the map the server saved, in .bt form, byte for byte.
#include <gtest/gtest.h>

#include <signal.h>

#include <atomic>
#include <mutex>
#include <sstream>
#include <thread>

#include "integration_harness.h"
#include "libbot_copy/raw_t.hpp"

namespace ort::test {
namespace {

// Every octomap.raw_t on a channel, decoded with the viewers' own type, on a thread.
class RawMapReceiver {
 public:
  RawMapReceiver(const std::string& url, const std::string& channel) : lcm_(url) {
    lcm_.subscribeFunction(channel, &RawMapReceiver::on_message, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(50);
    });
  }
  ~RawMapReceiver() {
    stop_ = true;
    thread_.join();
  }
  int64_t count() const { return count_; }
  int64_t undecodable() const { return undecodable_; }
  libbot_copy::raw_t latest() {
    std::lock_guard lock(mutex_);
    return latest_;
  }

 private:
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string&, RawMapReceiver* self) {
    libbot_copy::raw_t m;
    try {
      if (m.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) != static_cast<int>(rbuf->data_size)) {
        ++self->undecodable_;
        return;
      }
    } catch (const std::exception&) {
      ++self->undecodable_;
      return;
    }
    std::lock_guard lock(self->mutex_);
    self->latest_ = std::move(m);
    ++self->count_;
  }

  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> count_{0}, undecodable_{0};
  std::mutex mutex_;
  libbot_copy::raw_t latest_;
  std::thread thread_;
};

// OctoMap's own .bt of a tree: writeBinary turns a copy into maximum likelihood and prunes it.
std::string bt_bytes(const octomap::OcTree& tree) {
  octomap::OcTree copy(tree);
  std::ostringstream out;
  copy.writeBinary(out);
  return out.str();
}

TEST(ServerOctomapRaw, ViewersGetTheServersMapOnOctomap) {
  NetworkNamespace ns("octomap-raw");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("octomap-raw");
  const std::string url = test_lcm_url(23, ns.rmem_max());
  const std::string default_buffer_url = url.substr(0, url.find("&recv_buf_size"));
  StatusWatcher status(url);
  ASSERT_TRUE(status.good());
  RawMapReceiver viewer(default_buffer_url, "OCTOMAP");
  ChildProcess server({server_program(), "-r", "0.2", "--map", dir + "/map.ot", "--lcm-url", url, "--backend", "cpu",
                       "--octomap-raw-rate", "4", "--save-interval", "0"},
                      dir + "/server.log");
  ASSERT_TRUE(status.wait_for([](const auto&) { return true; }, 60)) << server.log();
  ChildProcess robot({client_program(), "replay", "synthetic", "--robot", "alpha", "--first", "0", "--count", "4",
                      "--rate", "5", "--decimate", "4", "--lcm-url", url},
                     dir + "/replay.log");
  ASSERT_EQ(robot.wait(120), 0) << robot.log();
  ASSERT_TRUE(status.wait_for([](const octomap_rt::server_status_t& s) { return total_applied(s) == 4; }, 120))
      << server.log();
  // Two periods after the last scan, what the viewer holds is the final map.
  const int64_t seen = viewer.count();
  for (int i = 0; i < 100 && viewer.count() < seen + 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const libbot_copy::raw_t last = viewer.latest();
  server.signal(SIGTERM);
  ASSERT_EQ(server.wait(60), 0) << server.log();
  EXPECT_EQ(viewer.undecodable(), 0);
  ASSERT_GE(viewer.count(), seen + 3) << "the viewer stopped getting OCTOMAP\n" << server.log();

  const auto saved = load_ot(dir + "/map.ot");
  ASSERT_TRUE(saved);
  const std::string bt = bt_bytes(*saved);
  ASSERT_EQ(last.length, static_cast<int32_t>(last.data.size()));
  EXPECT_TRUE(std::vector<uint8_t>(bt.begin(), bt.end()) == last.data)
      << "OCTOMAP carries " << last.length << " bytes, the saved map is " << bt.size() << " bytes of .bt";
  octomap::OcTree from_viewer(0.5);
  std::istringstream in(std::string(last.data.begin(), last.data.end()));
  ASSERT_TRUE(from_viewer.readBinary(in));
  EXPECT_EQ(from_viewer.getResolution(), 0.2);
  octomap::OcTree saved_as_bt(*saved);
  saved_as_bt.toMaxLikelihood();
  saved_as_bt.prune();
  EXPECT_EQ(from_viewer.getNumLeafNodes(), saved_as_bt.getNumLeafNodes());
  EXPECT_GT(last.utime, 0);
  EXPECT_EQ(last.transform[0][0], 1.0);
  EXPECT_EQ(last.transform[0][1], 0.0);
}

TEST(ServerOctomapRaw, AMapOverTheCapIsDepthLimitedAndTheStatusSaysSo) {
  NetworkNamespace ns("octomap-raw-cap");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("octomap-raw-cap");
  const std::string url = test_lcm_url(24, ns.rmem_max());
  StatusWatcher status(url);
  ASSERT_TRUE(status.good());
  RawMapReceiver viewer(url, "OCTOMAP");
  ChildProcess server({server_program(), "-r", "0.1", "--lcm-url", url, "--backend", "cpu", "--octomap-raw-rate", "4",
                       "--octomap-raw-max-kib", "8"},
                      dir + "/server.log");
  ASSERT_TRUE(status.wait_for([](const auto&) { return true; }, 60)) << server.log();
  ChildProcess robot({client_program(), "replay", "synthetic", "--robot", "alpha", "--first", "0", "--count", "2",
                      "--rate", "5", "--lcm-url", url},
                     dir + "/replay.log");
  ASSERT_EQ(robot.wait(120), 0) << robot.log();
  const auto noted = status.wait_for(
      [](const octomap_rt::server_status_t& s) {
        return total_applied(s) == 2 && s.message.find("OCTOMAP map depth-limited") != std::string::npos;
      },
      60);
  ASSERT_TRUE(noted) << (status.latest() ? status.latest()->message : "") << "\n" << server.log();
  const int64_t seen = viewer.count();
  for (int i = 0; i < 100 && viewer.count() < seen + 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const libbot_copy::raw_t last = viewer.latest();
  EXPECT_LE(last.data.size() + 148, 8u * 1024);  // the whole message within the cap
  octomap::OcTree coarse(0.5);
  std::istringstream in(std::string(last.data.begin(), last.data.end()));
  ASSERT_TRUE(coarse.readBinary(in));
  EXPECT_GT(coarse.getResolution(), 0.1);  // cut at a depth: coarser voxels
  EXPECT_GT(coarse.getNumLeafNodes(), 0u);
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(60), 0) << server.log();
}

}  // namespace
}  // namespace ort::test
