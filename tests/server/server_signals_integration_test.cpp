// Issue 13, findings 4 and 2 (exit status): the real octomap-rt-server process and its
// signals. A repeated SIGTERM/SIGINT is idempotent (it used to exit at once without saving
// anything); SIGQUIT exits at once but saves the map as applied; a failed final save still
// prints the summary and exits non-zero (it used to abort: exit 134). memq:// keeps the
// server alone: no network is involved.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "integration_harness.h"
#include "support/small_filesystem.h"

namespace ort::test {
namespace {

std::vector<std::string> server_args(const std::string& map) {
  return {server_program(), "-r",    "0.1", "--backend",       "cpu", "--lcm-url",
          "memq://",        "--map", map,   "--status-period", "0.2"};
}

bool wait_for_log(const ChildProcess& p, const std::string& text, double timeout_s) {
  const auto end = SteadyClock::now() + std::chrono::duration<double>(timeout_s);
  while (SteadyClock::now() < end) {
    if (p.log().find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

TEST(ServerSignals, ASecondSignalDuringTheStopChangesNothing) {
  const std::string dir = make_test_dir("signals-twice");
  ChildProcess server(server_args(dir + "/map.ot"), dir + "/server.log");
  ASSERT_TRUE(wait_for_log(server, "listening on", 60)) << server.log();
  server.signal(SIGTERM);
  server.signal(SIGINT);  // a different signal, so both are pending: the stop sees the second one
  const auto rc = server.wait(60);
  ASSERT_TRUE(rc.has_value()) << server.log();
  EXPECT_EQ(*rc, 0) << server.log();
  EXPECT_NE(server.log().find("already stopping"), std::string::npos) << server.log();
  EXPECT_NE(server.log().find("octomap-rt-server summary"), std::string::npos) << server.log();
  EXPECT_NE(load_ot(dir + "/map.ot"), nullptr) << "the map was not saved";
  std::filesystem::remove_all(dir);
}

TEST(ServerSignals, SigquitExitsAtOnceAndStillSavesTheMap) {
  const std::string dir = make_test_dir("signals-quit");
  ChildProcess server(server_args(dir + "/map.ot"), dir + "/server.log");
  ASSERT_TRUE(wait_for_log(server, "listening on", 60)) << server.log();
  server.signal(SIGQUIT);
  const auto rc = server.wait(60);
  ASSERT_TRUE(rc.has_value()) << server.log();
  EXPECT_EQ(*rc, 2) << server.log();
  EXPECT_NE(load_ot(dir + "/map.ot"), nullptr) << "the map as applied was not saved";
  std::filesystem::remove_all(dir);
}

TEST(ServerSignals, AFailedFinalSavePrintsTheSummaryAndExitsNonZero) {
  const std::string dir = make_test_dir("signals-full"), logs = make_test_dir("signals-full-log");
  const int rc = run_on_small_fs(dir, {.bytes = 64 * 1024}, [&] {
    ChildProcess server(server_args(dir + "/map.ot"), logs + "/server.log");
    if (!wait_for_log(server, "listening on", 60)) return 3;
    {
      std::ofstream filler(dir + "/filler", std::ios::binary);
      const std::string block(4096, 'x');
      while (filler.write(block.data(), block.size())) {}
    }
    server.signal(SIGTERM);
    const auto code = server.wait(60);
    if (!code) return 4;
    if (*code != 1) return 10 + *code;
    const std::string log = server.log();
    if (log.find("octomap-rt-server summary") == std::string::npos) return 5;
    return log.find("FINAL SAVE FAILED") == std::string::npos ? 6 : 0;
  });
  if (rc < 0) GTEST_SKIP() << "no user/mount namespaces here";
  std::ifstream in(logs + "/server.log");
  const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(rc, 0) << "3: never listened, 4: did not exit, 10+N: exit status N (144: aborted), 5: no summary, "
                      "6: no FINAL SAVE FAILED line\n"
                   << log;
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(logs);
}

}  // namespace
}  // namespace ort::test
