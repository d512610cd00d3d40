// The load test tool, short: 2 producers x 2 Hz x 3 s of small scans against a real server
// in the tool's own network namespace. Every published scan must be accounted for
// (received = applied + rejected + dropped, nothing in flight), the report must carry peak
// memory and latency, and the server must stop cleanly. No timing assertions.
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace ort::test {
namespace {

TEST(LoadTestSmoke, EveryScanIsAccountedFor) {
  const std::string log = testing::TempDir() + "/loadtest-smoke-server.log";
  const std::string cmd = std::string(OCTOMAP_RT_LOADTEST) +
                          " --producers 2 --rate 2 --duration 3 --points 2000 --log " + log +
                          " -- -r 0.2 --backend cpu 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  if (out.find("cannot make a private network namespace") != std::string::npos) GTEST_SKIP() << out;
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << out;
  EXPECT_NE(out.find("accounted:   yes"), std::string::npos) << out;
  EXPECT_NE(out.find("published 12, received 12 = applied 12"), std::string::npos) << out;
  EXPECT_NE(out.find("peak RSS"), std::string::npos) << out;
}

}  // namespace
}  // namespace ort::test
