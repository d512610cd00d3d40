// Issue 13, findings 3 and 2 (save part): a map file is loaded only when OctoMap's reader
// can consume it whole (truncated and altered files are refused, never overwritten), the
// server checks at start that it can save, and a failed save removes its .tmp.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <gtest/gtest.h>

#include "core/file_checks/octree_file_check.h"
#include "daemon/mapping_server.h"
#include "daemon/persistence/map_store.h"
#include "engine/map_engine.h"
#include "scene/synthetic_scene.h"
#include "server/scan_fixtures.h"
#include "support/small_filesystem.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

using Kind = daemon::MapStoreError::Kind;

std::string map_bytes(size_t scans) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = BackendKind::kCpu;
  MapEngine engine(o);
  auto tree = engine.make_tree();
  const ScanSet set = make_synthetic_rooms();
  for (size_t i = 0; i < scans; ++i) {
    const auto world = world_points(set.scans[i]);
    ShotScan shot;
    engine.insert(sensor_origin(set.scans[i]), std::span<const octomap::point3d>(&world[0], world.size()), *tree, shot);
  }
  return daemon::serialize_map(*tree);
}

void write(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

Kind load_error(const std::string& path) {
  try {
    daemon::load_map(path, 0.1);
  } catch (const daemon::MapStoreError& e) {
    return e.kind();
  }
  return Kind::kSerialize;  // "loaded": no map error
}

TEST(MapFileIntegrity, TruncatedOrAlteredMapsAreRefused) {
  const auto dir = temp_dir("map-integrity");
  const std::string good = map_bytes(4);
  const size_t data = check_octree_file(good).data_offset;
  ASSERT_GT(good.size(), data + 1000);
  write(dir + "/good.ot", good);
  ASSERT_NO_THROW(daemon::load_map(dir + "/good.ot", 0.1));

  std::vector<std::pair<std::string, std::string>> bad = {
      {"cut in half", good.substr(0, good.size() / 2)},
      {"cut to 200 bytes", good.substr(0, 200)},
      {"header only", good.substr(0, data)},
      {"one byte short", good.substr(0, good.size() - 1)},
      {"trailing bytes", good + "garbage"},
  };
  for (size_t at : {data + 3, data + 97, good.size() / 2, good.size() - 40}) {
    std::string altered = good;
    altered.replace(at, 8, "AAAAAAAA");
    bad.emplace_back("8 bytes overwritten at " + std::to_string(at), altered);
  }
  std::string header = good;
  header.replace(header.find("size ") + 5, 1, "9");  // the node count in the header
  bad.emplace_back("node count altered", header);
  for (const auto& [what, bytes] : bad) {
    write(dir + "/bad.ot", bytes);
    EXPECT_EQ(load_error(dir + "/bad.ot"), Kind::kCorrupt) << what << " was loaded";
  }
  std::filesystem::remove_all(dir);
}

TEST(MapFileIntegrity, ServerRefusesACorruptMapAndLeavesItAsItIs) {
  const auto dir = temp_dir("map-refuse");
  auto cfg = test_config(0.1, true);
  cfg.map_path = dir + "/map.ot";
  const std::string cut = map_bytes(3).substr(0, 5000);
  write(cfg.map_path, cut);
  std::ostringstream log;
  {
    lcm::LCM lc("memq://");
    try {
      daemon::MappingServer server(cfg, lc, log);
      FAIL() << "a truncated map was loaded";
    } catch (const daemon::MapStoreError& e) {
      EXPECT_EQ(e.kind(), Kind::kCorrupt);
      EXPECT_NE(std::string(e.what()).find("--move-corrupt-map-aside"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(read(cfg.map_path), cut) << "the refused file was changed";

  // With the flag: kept under another name, and a new map starts (and is saved at stop).
  cfg.move_corrupt_map_aside = true;
  {
    lcm::LCM lc("memq://");
    daemon::MappingServer server(cfg, lc, log);
    EXPECT_EQ(server.with_map([](const octomap::OcTree& t) { return t.size(); }), 0u);
    server.start();
    server.stop();
  }
  std::vector<std::string> aside;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().rfind("map.ot.corrupt-", 0) == 0) aside.push_back(e.path().string());
  ASSERT_EQ(aside.size(), 1u) << log.str();
  EXPECT_EQ(read(aside[0]), cut);
  EXPECT_NO_THROW(daemon::load_map(cfg.map_path, 0.1));
  EXPECT_NE(log.str().find("moved it to"), std::string::npos) << log.str();
  std::filesystem::remove_all(dir);
}

TEST(MapFileIntegrity, StartUpRefusesAMapDirectoryItCannotWrite) {
  const auto dir = temp_dir("map-readonly");
  auto cfg = test_config(0.1, true);
  cfg.map_path = dir + "/missing-dir/map.ot";
  {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    try {
      daemon::MappingServer server(cfg, lc, log);
      FAIL() << "started with a map directory that does not exist";
    } catch (const daemon::MapStoreError& e) {
      EXPECT_EQ(e.kind(), Kind::kNotWritable) << e.what();
    }
  }
  cfg.map_path = dir + "/map.ot";
  const int rc = run_on_small_fs(dir, {.bytes = 1 << 20, .read_only = true}, [&] {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    try {
      daemon::MappingServer server(cfg, lc, log);
    } catch (const daemon::MapStoreError& e) {
      return e.kind() == Kind::kNotWritable && std::string(e.what()).find("Read-only") != std::string::npos ? 0 : 3;
    }
    return 4;  // started on a read-only file system
  });
  if (rc < 0) GTEST_SKIP() << "no user/mount namespaces here";
  EXPECT_EQ(rc, 0) << "3: wrong error, 4: started on a read-only map directory";
  std::filesystem::remove_all(dir);
}

TEST(MapFileIntegrity, FailedSaveRemovesItsTmpAndLeavesThePreviousMap) {
  const auto dir = temp_dir("map-full");
  const std::string small = map_bytes(1), big = map_bytes(6);
  const int rc = run_on_small_fs(dir, {.bytes = small.size() + 16 * 1024}, [&] {
    const std::string path = dir + "/map.ot";
    daemon::write_file_atomically(path, small);
    try {
      daemon::write_file_atomically(path, big + std::string(small.size() + 64 * 1024, 'x'));
      return 3;  // a save larger than the disk succeeded
    } catch (const daemon::MapStoreError& e) {
      if (e.kind() != Kind::kWrite && e.kind() != Kind::kSync) return 4;
    }
    if (std::filesystem::exists(path + ".tmp")) return 5;
    return read(path) == small ? 0 : 6;
  });
  if (rc < 0) GTEST_SKIP() << "no user/mount namespaces here";
  EXPECT_EQ(rc, 0) << "3: no error on a full disk, 4: wrong error kind, 5: .tmp left behind, 6: previous map lost";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
