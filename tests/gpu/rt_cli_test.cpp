// `octomap-rt build --backend rt` from the command line: exact mode either builds a map (a
// device with ray tracing) or fails with one clear "unsupported: ..." line naming the missing
// extensions (lavapipe, CI); octomap mode is always refused with the reason.
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace {

struct Result {
  int status = -1;
  std::string output;
};

Result run(const std::string& args) {
  const std::string cmd = std::string(OCTOMAP_RT_CLI) + " " + args + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof(buf), p)) r.output.append(buf, n);
  r.status = pclose(p);
  return r;
}

TEST(RtCli, ExactModeBuildsOrRefusesCleanly) {
  const auto out = std::filesystem::temp_directory_path() / "octomap_rt_rt_cli_test.bt";
  std::filesystem::remove(out);
  const Result r = run("build synthetic -q -r 0.4 --backend rt --traversal exact -o " + out.string());
  if (r.status == 0) {
    EXPECT_TRUE(std::filesystem::exists(out)) << r.output;
  } else {
    EXPECT_NE(r.output.find("unsupported:"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("VK_KHR_ray_tracing_pipeline"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << r.output;  // no crash
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  std::filesystem::remove(out);
}

TEST(RtCli, OctomapModeIsRefusedWithTheReason) {
  const Result r = run("build synthetic -q -r 0.4 --backend rt -o /dev/null");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("unsupported: the rt back end implements --traversal exact only"), std::string::npos)
      << r.output;
}

}  // namespace
