// The server's persistence: the map and its applied order are saved at stop (and
// periodically); a restart loads both, refuses another resolution, and later scans extend
// the map exactly as if one server had applied everything in the recorded order.
#include <filesystem>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/persistence/map_identity_file.h"
#include "daemon/persistence/map_store.h"
#include "scene/synthetic_scene.h"
#include "server/scan_fixtures.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

void feed(daemon::MappingServer& server, lcm::LCM& lc, const ScanSet& set, size_t from, size_t to) {
  for (size_t k = from; k < to; ++k) {
    const auto msg = scan_message(set.scans[k], "rover", static_cast<int64_t>(k));
    lc.publish("OCTOMAP_RT_SCAN_ROVER", &msg);
  }
  ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(to - from)));
}

TEST(ServerPersistence, SaveOnStopRestartLoadsAndExtends) {
  const ScanSet set = make_synthetic_rooms();
  const auto dir = temp_dir("server-persist");
  auto cfg = test_config(0.1, true);
  cfg.map_path = dir + "/map.ot";
  std::ostringstream log;
  {
    lcm::LCM lc("memq://");
    daemon::MappingServer server(cfg, lc, log);
    server.start();
    feed(server, lc, set, 0, 3);
    server.stop();
  }
  ASSERT_TRUE(std::filesystem::exists(cfg.map_path));
  const auto first = daemon::read_applied_order(cfg.map_path + ".order");
  EXPECT_EQ(first.entries.size(), 3u);
  const auto identity = daemon::read_map_identity(cfg.map_path);
  ASSERT_TRUE(identity.has_value());
  EXPECT_EQ(identity->map_bytes, std::filesystem::file_size(cfg.map_path));
  EXPECT_EQ(identity->order_entries, 3u);

  // Another resolution: refused with a clear message, the file untouched.
  {
    auto other = cfg;
    other.engine.resolution = 0.2;
    lcm::LCM lc("memq://");
    try {
      daemon::MappingServer server(other, lc, log);
      FAIL() << "a 0.1 m map was served at 0.2 m";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
    }
  }

  {
    lcm::LCM lc("memq://");
    daemon::MappingServer server(cfg, lc, log);
    EXPECT_EQ(server.applied_order().size(), 3u);
    server.start();
    feed(server, lc, set, 3, 6);
    server.stop();
    EXPECT_EQ(server.applied_order().size(), 6u);
  }
  const auto all = daemon::read_applied_order(cfg.map_path + ".order");
  ASSERT_EQ(all.entries.size(), 6u);
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(all.entries[i].seq, static_cast<int64_t>(i));

  const auto saved = daemon::load_map(cfg.map_path, 0.1);
  const auto ref = engine_reference(cfg, all.entries, [&](const std::string&, int64_t seq) -> const PosedScan& {
    return set.scans.at(static_cast<size_t>(seq));
  });
  const TreeDiff d = compare_leaves(*saved, *ref);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
  std::filesystem::remove_all(dir);
}

TEST(ServerPersistence, PeriodicSavesHappenWhileServing) {
  const ScanSet set = make_synthetic_rooms();
  const auto dir = temp_dir("server-periodic");
  auto cfg = test_config(0.1, true);
  cfg.map_path = dir + "/map.ot";
  cfg.save_interval_s = 0.2;
  std::ostringstream log;
  lcm::LCM lc("memq://");
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  feed(server, lc, set, 0, 2);
  // A periodic save (no stop yet) captures the map after both scans: the map changes only
  // between whole scans, and the map's identity (written after the map) says how many of the
  // order file's scans it holds.
  size_t saved_scans = 0;
  for (int i = 0; i < 250 && saved_scans < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (const auto id = daemon::read_map_identity(cfg.map_path)) saved_scans = id->order_entries;
  }
  EXPECT_EQ(saved_scans, 2u);
  EXPECT_GE(daemon::read_applied_order(cfg.map_path + ".order").entries.size(), 2u);
  EXPECT_NO_THROW(daemon::load_map(cfg.map_path, 0.1));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const int64_t saves = server.status().map_saves;
  EXPECT_GE(saves, 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_EQ(server.status().map_saves, saves) << "an unchanged map is not saved again";
  server.stop();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
