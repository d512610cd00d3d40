// `octomap-rt status` against a real octomap-rt-server in a network namespace: text, JSON
// (checked by Python's json module), --watch, and the error when nobody answers.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "integration_harness.h"

namespace ort::test {
namespace {

std::string first_line_starting(const std::string& text, char c) {
  size_t start = 0;
  while (start < text.size()) {
    const size_t nl = text.find('\n', start);
    const std::string line = text.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
    if (!line.empty() && line[0] == c) return line;
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  return "";
}

size_t count_of(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(StatusIntegration, ShowsARunningServerAsTextJsonAndWatch) {
  NetworkNamespace ns("status");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("status");
  const std::string url = test_lcm_url(11, ns.rmem_max());
  StatusWatcher status(url);
  ASSERT_TRUE(status.good());
  ChildProcess server({server_program(), "-r", "0.2", "--map", dir + "/map.ot", "--lcm-url", url, "--backend", "cpu"},
                      dir + "/server.log");
  ASSERT_TRUE(status.wait_for([](const auto&) { return true; }, 60)) << server.log();

  ChildProcess robot({client_program(), "replay", "synthetic", "--robot", "alpha", "--first", "0", "--count", "3",
                      "--rate", "10", "--decimate", "8", "--lcm-url", url},
                     dir + "/replay.log");
  ASSERT_EQ(robot.wait(120), 0) << robot.log();
  {  // one message that is not a scan: counted with its reason
    lcm::LCM lc(url);
    const char junk[16] = "not a scan_t";
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", junk, sizeof junk);
  }
  ChildProcess query(
      {client_program(), "query", "points", "0,0,0", "1,1,1", "--client-id", "planner1", "--lcm-url", url},
      dir + "/query.log");
  ASSERT_EQ(query.wait(60), 0) << query.log();
  ASSERT_TRUE(status.wait_for(
      [](const octomap_rt::server_status_t& s) {
        const auto* r = find_robot_ci(s, "alpha");
        return r && r->scans_applied == 3 && r->scans_rejected == 1 && s.queries_answered == 1;
      },
      120))
      << server.log();

  ChildProcess text({client_program(), "status", "--lcm-url", url}, dir + "/text.log");
  ASSERT_EQ(text.wait(30), 0) << text.log();
  const std::string t = text.log();
  EXPECT_NE(t.find("(pid " + std::to_string(server.pid()) + " on "), std::string::npos) << t;
  EXPECT_NE(t.find("back end  cpu"), std::string::npos) << t;
  EXPECT_NE(t.find("rejected: wrong fingerprint 1"), std::string::npos) << t;
  EXPECT_NE(t.find("queries   received 1: answered 1, bad 0"), std::string::npos) << t;
  EXPECT_NE(t.find("  planner1 "), std::string::npos) << t;

  ChildProcess json({client_program(), "status", "--json", "--lcm-url", url}, dir + "/json.log");
  ASSERT_EQ(json.wait(30), 0) << json.log();
  std::ofstream(dir + "/status.json") << first_line_starting(json.log(), '{') << "\n";
  const std::string check =
      "python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); r=[r for r in s[\"robots\"] if "
      "r[\"robot_id\"].lower()==\"alpha\"][0]; assert s[\"pid\"]==int(sys.argv[2]), s; "
      "assert r[\"scans_applied\"]==3 and r[\"reject_reasons\"]=={\"wrong fingerprint\":1}, r; "
      "assert s[\"state_name\"] in (\"RUNNING\",\"DEGRADED\"), s; q=s[\"queries\"]; "
      "assert q[\"answered\"]==1 and [c[\"client_id\"] for c in q[\"clients\"]]==[\"planner1\"], q' " +
      dir + "/status.json " + std::to_string(server.pid());
  EXPECT_EQ(std::system(check.c_str()), 0) << json.log();

#ifdef OCTOMAP_RT_JAVA_EXAMPLE_CP
  // A Java program with lcm.jar and our types jar decodes the same status (Java's LCM takes no
  // recv_buf_size; a status is one datagram).
  ChildProcess java({"java", "-Djava.net.preferIPv4Stack=true", "-cp", OCTOMAP_RT_JAVA_EXAMPLE_CP, "StatusListener",
                     url.substr(0, url.find("&recv_buf_size")), "1"},
                    dir + "/java.log");
  ASSERT_EQ(java.wait(60), 0) << java.log();
  EXPECT_NE(java.log().find("robot ALPHA: received 4, applied 3, rejected 1"), std::string::npos) << java.log();
#endif

  ChildProcess watch({client_program(), "status", "--watch", "--count", "2", "--lcm-url", url}, dir + "/watch.log");
  ASSERT_EQ(watch.wait(30), 0) << watch.log();
  EXPECT_EQ(count_of(watch.log(), "(pid " + std::to_string(server.pid()) + " on "), 2u) << watch.log();

  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(60), 0) << server.log();
  ChildProcess nobody({client_program(), "status", "--timeout", "1", "--lcm-url", url}, dir + "/nobody.log");
  EXPECT_NE(nobody.wait(30), 0);
  EXPECT_NE(nobody.log().find("no status on OCTOMAP_RT_STATUS within 1 s"), std::string::npos) << nobody.log();
}

}  // namespace
}  // namespace ort::test
