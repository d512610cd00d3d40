// Prior maps (octomap_server's map file at start), in one process over memq://: a server
// starts from a .bt or a .ot, at the file's resolution when -r is not given, and saves the
// new map of record to another file; the prior is a new history (state id 1, a new epoch)
// and is never written; once the map of record exists it is what a restart loads.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "daemon/persistence/map_store.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

namespace fs = std::filesystem;

// A map as a robot made it: OctoMap's own insertPointCloud of two walls seen from the origin.
octomap::OcTree prior_tree(double res) {
  octomap::OcTree t(res);
  for (int k = 0; k < 2; ++k) {
    octomap::Pointcloud cloud;
    for (int i = 0; i < 30; ++i)
      for (int j = 0; j < 10; ++j) cloud.push_back(3.05f + k, -1.5f + 0.1f * i, 0.05f + 0.1f * j);
    t.insertPointCloud(cloud, octomap::point3d(0, 0, 0.5));
  }
  return t;
}

daemon::ServerConfig prior_config(const std::string& dir, const std::string& prior) {
  auto cfg = test_config(0.05, true);  // -r not given: the file's resolution wins
  cfg.resolution_from_file = true;
  cfg.prior_path = prior;
  cfg.map_path = dir + "/map.ot";
  cfg.save_interval_s = 0;
  return cfg;
}

TEST(PriorMap, ABtPriorStartsANewMapAtItsResolutionSavedElsewhere) {
  const auto dir = temp_dir("prior-bt");
  octomap::OcTree prior = prior_tree(0.2);
  const std::string bt = dir + "/prior.bt";
  {
    octomap::OcTree copy(prior);
    ASSERT_TRUE(copy.writeBinary(bt));
  }
  const auto bt_before = fs::last_write_time(bt);
  const auto cfg = prior_config(dir, bt);
  int64_t epoch = 0;
  {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    daemon::MappingServer server(cfg, lc, log);
    const auto st = server.status();
    EXPECT_DOUBLE_EQ(st.resolution, 0.2) << log.str();
    EXPECT_EQ(st.map_version, 1) << "the prior is the map's first change";
    EXPECT_NE(st.map_epoch, 0);
    epoch = st.map_epoch;
    // Every voxel of the prior has its class, at the server's clamping bounds (max likelihood).
    server.with_map([&](const octomap::OcTree& t) {
      size_t known = 0;
      for (auto it = prior.begin_leafs(); it != prior.end_leafs(); ++it, ++known) {
        const octomap::OcTreeNode* n = t.search(it.getKey());
        EXPECT_TRUE(n && t.isNodeOccupied(n) == prior.isNodeOccupied(*it));
        if (n) {
          EXPECT_TRUE(n->getLogOdds() == t.getClampingThresMaxLog() || n->getLogOdds() == t.getClampingThresMinLog());
        }
      }
      EXPECT_GT(known, 100u);
      return 0;
    });
    server.start();
    const auto s = wall_scan(3);  // x = 6.05: new space
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
    ASSERT_TRUE(wait_until_done(server, 1));
    EXPECT_EQ(server.status().map_version, 2);
    ASSERT_TRUE(server.stop());
  }
  EXPECT_EQ(fs::last_write_time(bt), bt_before) << "the prior was written";
  ASSERT_TRUE(fs::exists(cfg.map_path));
  // The map of record exists now: a restart loads it (same history), not the prior again.
  lcm::LCM lc("memq://");
  std::ostringstream log;
  daemon::MappingServer again(cfg, lc, log);
  EXPECT_EQ(again.status().map_epoch, epoch);
  EXPECT_EQ(again.status().map_version, 2);
  EXPECT_NE(log.str().find("the prior " + bt + " is not"), std::string::npos) << log.str();
  fs::remove_all(dir);
}

TEST(PriorMap, AnOtPriorKeepsItsLogOddsAndAnotherResolutionIsRefused) {
  const auto dir = temp_dir("prior-ot");
  const octomap::OcTree prior = prior_tree(0.1);
  const std::string ot = dir + "/prior.ot";
  ASSERT_TRUE(prior.write(ot));
  {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    daemon::MappingServer server(prior_config(dir, ot), lc, log);
    const TreeDiff d = server.with_map([&](const octomap::OcTree& t) { return compare_leaves(t, prior); });
    EXPECT_TRUE(d.maps_equal()) << d.first_difference;
    EXPECT_EQ(server.status().map_version, 1);
  }
  auto fixed = prior_config(dir, ot);
  fixed.resolution_from_file = false;
  fixed.engine.resolution = 0.2;
  lcm::LCM lc("memq://");
  std::ostringstream log;
  try {
    daemon::MappingServer server(fixed, lc, log);
    FAIL() << "a 0.1 m prior was served at 0.2 m";
  } catch (const daemon::MapStoreError& e) {
    EXPECT_EQ(e.kind(), daemon::MapStoreError::Kind::kWrongResolution);
    EXPECT_NE(std::string(e.what()).find("--prior"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(PriorMap, ABtCannotBeTheMapOfRecord) {
  const auto dir = temp_dir("prior-record");
  octomap::OcTree t = prior_tree(0.1);
  ASSERT_TRUE(t.writeBinary(dir + "/map.bt"));
  EXPECT_THROW(daemon::load_map(dir + "/map.bt", 0.1), daemon::MapStoreError);
  EXPECT_DOUBLE_EQ(daemon::map_file_resolution(dir + "/map.bt"), 0.1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
