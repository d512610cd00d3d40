// `cmake --install` and find_package(octomap_rt): the install tree of this build holds what a
// planner's project needs; client/examples/map_fetch (the map client) and query_point (the
// query client, namespace ort::client alone) are configured and built out of tree against it
// and run against a real server in a network namespace.
#include <gtest/gtest.h>

#include <signal.h>

#include <cstdlib>
#include <filesystem>

#include "integration_harness.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

int run(const std::string& cmd, const std::string& log) { return std::system((cmd + " > " + log + " 2>&1").c_str()); }

TEST(InstallIntegration, AnOutOfTreeProgramBuildsAgainstTheInstallAndFetchesTheMap) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  NetworkNamespace ns("install");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("install");
  const std::string prefix = dir + "/prefix", ex = dir + "/example";
  ASSERT_EQ(
      run("cmake --install " OCTOMAP_RT_BUILD_DIR " --component Unspecified --prefix " + prefix, dir + "/install.log"),
      0)
      << dir << "/install.log";
  EXPECT_TRUE(std::filesystem::exists(prefix + "/lib/cmake/octomap_rt/octomap_rtConfig.cmake"));
  EXPECT_TRUE(std::filesystem::exists(prefix + "/bin/octomap-rt-server"));
  EXPECT_TRUE(std::filesystem::exists(prefix + "/include/octomap_rt/octomap_rt/map_chunk_t.hpp"));
  EXPECT_TRUE(std::filesystem::exists(prefix + "/include/octomap_rt/query_client/client.h"));
  ASSERT_EQ(
      run("cmake -S " OCTOMAP_RT_SOURCE_DIR "/client/examples/map_fetch -B " + ex + " -DCMAKE_PREFIX_PATH=" + prefix,
          dir + "/configure.log"),
      0)
      << dir << "/configure.log";
  ASSERT_EQ(run("cmake --build " + ex, dir + "/build.log"), 0) << dir << "/build.log";
  const std::string qp = dir + "/query_point";
  ASSERT_EQ(
      run("cmake -S " OCTOMAP_RT_SOURCE_DIR "/client/examples/query_point -B " + qp + " -DCMAKE_PREFIX_PATH=" + prefix,
          dir + "/configure_query_point.log"),
      0)
      << dir << "/configure_query_point.log";
  ASSERT_EQ(run("cmake --build " + qp, dir + "/build_query_point.log"), 0) << dir << "/build_query_point.log";

  const std::string url = test_lcm_url(4, ns.rmem_max());
  StatusWatcher status(url);
  ChildProcess server({prefix + "/bin/octomap-rt-server", "-r", "0.2", "--lcm-url", url}, dir + "/server.log");
  ASSERT_TRUE(status.wait_for([&](const auto& s) { return s.pid == server.pid(); }, 60)) << server.log();
  ChildProcess replay({client_program(), "replay", graph, "--robot", "alpha", "--count", "1", "--lcm-url", url, "-q"},
                      dir + "/replay.log");
  EXPECT_EQ(replay.wait(120), 0) << replay.log();
  ASSERT_TRUE(status.wait_for([&](const auto& s) { return s.pid == server.pid() && total_applied(s) == 1; }, 240))
      << server.log();
  ChildProcess fetch({ex + "/map_fetch", url.substr(0, url.find("&recv_buf_size"))}, dir + "/map_fetch.log");
  ASSERT_EQ(fetch.wait(120), 0) << fetch.log();
  EXPECT_NE(fetch.log().find("snapshot 1: 1 scans"), std::string::npos) << fetch.log();
  EXPECT_NE(fetch.log().find("mirror at map state 1"), std::string::npos) << fetch.log();
  ChildProcess point({qp + "/query_point", url.substr(0, url.find("&recv_buf_size")), "0", "0", "-100"},
                     dir + "/query_point.log");
  ASSERT_EQ(point.wait(60), 0) << point.log();
  EXPECT_NE(point.log().find("map state 1: unknown"), std::string::npos) << point.log();
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(120), 0) << server.log();
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
