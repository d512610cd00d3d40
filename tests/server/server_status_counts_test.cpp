// The status's map figures on a map big enough that its leaves are not counted at every
// status (daemon/mapping_server_status.cpp: the count walks the whole tree under the map lock).
#include <sstream>

#include <gtest/gtest.h>

#include "daemon/mapping_server.h"
#include "octomap_rt/wire_contract.hpp"
#include "scene/scan_set.h"
#include "server/scan_fixtures.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

// A big map's leaves are counted (a walk of the whole tree under the map lock) at most every
// 10 s while scans are applied, and once more when the pipeline has drained: the status after
// stop() still has OctoMap's own figures, though statuses were taken while the map grew.
TEST(ServerStatusCounts, BigMapIsExactOnceDrained) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.status_period_s = 0.02;
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "husky1", static_cast<int64_t>(k));
    lc.publish(std::string(octomap_rt::wire::kScanChannelPrefix) + "HUSKY1", &msg);
    ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(k + 1)));
    (void)server.status();  // a status while the map grows
  }
  server.stop();
  const auto status = server.status();
  server.with_map([&](const octomap::OcTree& t) {
    EXPECT_GT(t.size(), 65'536u) << "a map big enough for the throttled count";
    EXPECT_EQ(status.num_nodes, static_cast<int64_t>(t.size()));
    EXPECT_EQ(status.num_leaf_nodes, static_cast<int64_t>(t.getNumLeafNodes()));
    EXPECT_NEAR(static_cast<double>(status.memory_bytes), static_cast<double>(t.memoryUsage()), 1024.0);
    return 0;
  });
}

}  // namespace
}  // namespace ort::test
