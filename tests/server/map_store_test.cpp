// Persistence pieces: .ot round trip, resolution mismatch refused, saves that survive
// SIGKILL at any moment, the applied-order file, and the LCM URL / kernel counter helpers.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "daemon/map/applied_order.h"
#include "daemon/persistence/map_store.h"
#include "daemon/transport/kernel_udp_stats.h"
#include "daemon/transport/server_lcm_url.h"
#include "engine/map_engine.h"
#include "scene/synthetic_scene.h"
#include "server/scan_fixtures.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

std::unique_ptr<octomap::OcTree> synthetic_map(double res, size_t scans) {
  EngineOptions o;
  o.resolution = res;
  o.backend.kind = BackendKind::kCpu;
  MapEngine engine(o);
  auto tree = engine.make_tree();
  const ScanSet set = make_synthetic_rooms();
  for (size_t i = 0; i < scans && i < set.scans.size(); ++i) {
    const auto world = world_points(set.scans[i]);
    ShotScan shot;
    engine.insert(sensor_origin(set.scans[i]), std::span<const octomap::point3d>(&world[0], world.size()), *tree, shot);
  }
  return tree;
}

TEST(MapStore, SaveLoadRoundTripKeepsEveryNodeAndLogOdds) {
  const auto dir = temp_dir("store-roundtrip");
  const auto tree = synthetic_map(0.1, 2);
  const std::string path = dir + "/map.ot";
  daemon::write_file_atomically(path, daemon::serialize_map(*tree));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const auto back = daemon::load_map(path, 0.1);
  EXPECT_EQ(compare_structure(*tree, *back), "");
  EXPECT_TRUE(compare_leaves(*tree, *back).maps_equal());
  std::filesystem::remove_all(dir);
}

TEST(MapStore, ResolutionMismatchIsRefusedClearly) {
  const auto dir = temp_dir("store-res");
  const std::string path = dir + "/map.ot";
  daemon::write_file_atomically(path, daemon::serialize_map(*synthetic_map(0.1, 1)));
  try {
    daemon::load_map(path, 0.05);
    FAIL() << "a 0.1 m map loaded as 0.05 m";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("resolution 0.1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("-r 0.05"), std::string::npos) << msg;
  }
  EXPECT_THROW(daemon::load_map(dir + "/missing.ot", 0.1), std::runtime_error);
  { std::ofstream(dir + "/junk.ot") << "not a map\n"; }
  EXPECT_THROW(daemon::load_map(dir + "/junk.ot", 0.1), std::runtime_error);
  std::filesystem::remove_all(dir);
}

// A child process saves two different maps over one path in a loop; the parent SIGKILLs it
// at random moments. Whatever the moment, the path holds one of the two complete maps.
TEST(MapStore, SaveIsAtomicUnderSigkill) {
  const auto dir = temp_dir("store-kill");
  const std::string path = dir + "/map.ot";
  const std::string bytes_a = daemon::serialize_map(*synthetic_map(0.1, 2));
  const std::string bytes_b = daemon::serialize_map(*synthetic_map(0.1, 4));
  ASSERT_NE(bytes_a.size(), bytes_b.size());
  daemon::write_file_atomically(path, bytes_a);
  std::mt19937 rng(7);
  int killed_mid_save = 0;
  const int kills = 15;
  for (int i = 0; i < kills; ++i) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      for (int k = 0;; ++k) daemon::write_file_atomically(path, k % 2 ? bytes_a : bytes_b);
    }
    ::usleep(20'000 + rng() % 60'000);
    ::kill(pid, SIGKILL);
    int st = 0;
    ::waitpid(pid, &st, 0);
    ASSERT_TRUE(WIFSIGNALED(st));
    killed_mid_save += std::filesystem::exists(path + ".tmp") ? 1 : 0;
    std::ifstream in(path, std::ios::binary);
    const std::string got((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(got == bytes_a || got == bytes_b)
        << "kill " << i << ": the map file is neither complete map (" << got.size() << " bytes)";
    EXPECT_NO_THROW(daemon::load_map(path, 0.1));
  }
  // Evidence the kills landed inside saves (a .tmp was being written), not only between them.
  EXPECT_GT(killed_mid_save, 0);
  std::filesystem::remove_all(dir);
}

// The order file is appended to, cut back to the entries a saved map holds, and an older
// server's v1 file (rewritten whole at every save) is taken over.
TEST(AppliedOrder, AppendedCutBackAndAnOldFileTakenOver) {
  const auto dir = temp_dir("applied-order");
  const std::string path = dir + "/map.ot.order";
  const std::vector<daemon::AppliedEntry> e = {{"husky1", 0, 100}, {"husky2", 0, 150}, {"husky1", 1, 200}};
  {
    daemon::AppliedOrder order;
    EXPECT_EQ(order.open_file(path, std::nullopt), 0u);
    for (const auto& x : e) order.append(x);
    order.sync();
    EXPECT_EQ(daemon::read_applied_order(path).entries, e);
    order.append({"husky2", 1, 250});
  }  // unsynced lines are written when the order is closed
  EXPECT_EQ(daemon::read_applied_order(path).entries.size(), 4u);
  {
    daemon::AppliedOrder order;  // a map saved after 2 scans: the later lines are cut off
    EXPECT_EQ(order.open_file(path, 2), 2u);
    order.append({"husky3", 0, 300});
    order.sync();
    const auto f = daemon::read_applied_order(path);
    ASSERT_EQ(f.entries.size(), 3u);
    EXPECT_EQ(f.entries[1], e[1]);
    EXPECT_EQ(f.entries[2].robot_id, "husky3");
  }
  {
    std::ofstream v1(path, std::ios::trunc);
    v1 << "# octomap-rt applied order v1\n# columns: index robot_id seq utime\n# scans 2\n# map_bytes 12345\n"
       << "0 husky1 0 100\n1 husky2 0 150\n";
  }
  {
    daemon::AppliedOrder order;
    EXPECT_EQ(order.open_file(path, std::nullopt), 2u);
    order.append(e[2]);
    order.sync();
  }
  const auto f = daemon::read_applied_order(path);
  EXPECT_EQ(f.entries, e);
  EXPECT_EQ(f.map_bytes, -1) << "rewritten as v2";
  std::filesystem::remove_all(dir);
}

TEST(AppliedOrder, BadFilesAreRefused) {
  std::istringstream bad("# octomap-rt applied order v1\n0 a 1 2\n2 b 1 2\n");
  EXPECT_THROW(daemon::parse_applied_order(bad), std::runtime_error);
  std::istringstream short_file("# scans 3\n0 a 1 2\n");
  EXPECT_THROW(daemon::parse_applied_order(short_file), std::runtime_error);
}

TEST(LcmUrl, DefaultIsHostLocalWithCappedReceiveBuffer) {
  ::unsetenv("LCM_DEFAULT_URL");
  auto c = daemon::choose_lcm_url("", 16u << 20, 4u << 20);
  EXPECT_EQ(c.url, "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  EXPECT_NE(c.warning.find("sysctl -w net.core.rmem_max=16777216"), std::string::npos) << c.warning;
  c = daemon::choose_lcm_url("", 16u << 20, 64u << 20);
  EXPECT_EQ(c.url, "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216");
  EXPECT_EQ(c.warning, "");
  c = daemon::choose_lcm_url("udpm://239.255.76.67:7700", 1000, 4000);
  EXPECT_EQ(c.url, "udpm://239.255.76.67:7700?recv_buf_size=1000");
  c = daemon::choose_lcm_url("udpm://239.255.76.67:7700?recv_buf_size=8000", 1000, 4000);
  EXPECT_EQ(c.url, "udpm://239.255.76.67:7700?recv_buf_size=8000");
  EXPECT_NE(c.warning, "");  // asks for more than the kernel gives
  EXPECT_EQ(daemon::choose_lcm_url("memq://", 1000, 4000).url, "memq://");
  ::setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7999?ttl=0&recv_buf_size=2000", 1);
  EXPECT_EQ(daemon::choose_lcm_url("", 1000, 4000).url, "udpm://239.255.76.67:7999?ttl=0&recv_buf_size=2000");
  ::unsetenv("LCM_DEFAULT_URL");
}

TEST(KernelUdpStats, ParsesRcvbufErrors) {
  std::istringstream snmp(
      "Ip: Forwarding DefaultTTL\nIp: 1 64\n"
      "Udp: InDatagrams NoPorts InErrors OutDatagrams RcvbufErrors SndbufErrors InCsumErrors IgnoredMulti MemErrors\n"
      "Udp: 100 0 236 50 236 0 0 0 0\n");
  EXPECT_EQ(daemon::parse_udp_rcvbuf_errors(snmp), 236);
  EXPECT_GE(daemon::read_udp_rcvbuf_errors(), 0);  // this machine's /proc/net/snmp
}

TEST(KernelUdpStats, ParsesOwnSocketDrops) {
  std::istringstream udp(
      "   sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ref pointer drops\n"
      "  1: 00000000:1DF3 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 4242 2 0000000000000000 17\n"
      "  2: 00000000:1DF3 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 777 2 0000000000000000 5\n");
  EXPECT_EQ(daemon::parse_udp_socket_drops(udp, {4242}), 17);
  EXPECT_GE(daemon::read_own_udp_drops(), 0);
}

}  // namespace
}  // namespace ort::test
