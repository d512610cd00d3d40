// The map's identity across restarts, in one process over memq:// (docs/PROTOCOL.md "Ids"):
// every change is counted and persisted (scans and edits), a clean restart keeps epoch and
// state id, and every path that forks the history gets a new epoch: a reset, a crash (the
// files as a running server left them), a map file replaced behind the server's back, a copy
// at another path, an old map without an identity. Also the lock: one daemon per map file.
#include <filesystem>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/persistence/map_file_lock.h"
#include "daemon/persistence/map_identity_file.h"
#include "daemon/persistence/map_store.h"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/channels.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

namespace fs = std::filesystem;

struct Identity {
  int64_t epoch = 0, state_id = 0;
  bool operator==(const Identity&) const = default;
};
std::ostream& operator<<(std::ostream& o, const Identity& i) {
  return o << "epoch " << i.epoch << " id " << i.state_id;
}

Identity identity_of(daemon::MappingServer& s) {
  const auto st = s.status();
  return {st.map_epoch, st.map_version};
}

daemon::ServerConfig config_at(const std::string& map_path) {
  auto cfg = test_config(0.1, true);
  cfg.map_path = map_path;
  cfg.queries.control_token = kToken;
  cfg.save_interval_s = 0;  // saves only at stop unless a test asks
  return cfg;
}

// Runs a server on `cfg` for `scans` wall scans (seq from `first`) and `edits` clear-boxes,
// then stops it cleanly; returns its identity at the end.
Identity run_server(const daemon::ServerConfig& cfg, int64_t first, int scans, int edits = 0, bool reset = false) {
  QueryServer fixture(cfg);
  auto& [lc, log, server, replies] = fixture;
  for (int k = 0; k < scans; ++k) {
    const auto s = wall_scan(first + k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
  }
  EXPECT_TRUE(wait_until_done(server, scans));
  auto edit = [&](int64_t id, int8_t op) {
    octomap_rt::map_edit_t e{};
    e.request_id = id, e.client_id = "op", e.reply_channel = kReply, e.op = op;
    const double lo[3] = {2.5, -2, 0}, hi[3] = {3.5, 2, 1};
    std::copy(lo, lo + 3, e.box_min), std::copy(hi, hi + 3, e.box_max);
    sign(e);
    lc.publish(ort::protocol::kMapEditChannel, &e);
    EXPECT_EQ(replies.wait_for<octomap_rt::map_edit_ack_t>(id).status, Reply::REPLY_OK);
  };
  for (int i = 0; i < edits; ++i) edit(10 + i, octomap_rt::map_edit_t::OP_CLEAR_TO_FREE);
  if (reset) edit(99, octomap_rt::map_edit_t::OP_RESET);
  const Identity id = identity_of(server);
  EXPECT_TRUE(server.stop()) << log.str();
  return id;
}

// Loads a server on `cfg` without running it: the identity it starts at.
Identity start_identity(const daemon::ServerConfig& cfg) {
  lcm::LCM lc("memq://");
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  return identity_of(server);
}

TEST(MapIdentity, ACleanRestartKeepsEpochAndIdAndEditsAreCounted) {
  const auto dir = temp_dir("identity-clean");
  const auto cfg = config_at(dir + "/map.ot");
  const Identity a = run_server(cfg, 0, 3, /*edits=*/2);
  EXPECT_NE(a.epoch, 0);
  EXPECT_EQ(a.state_id, 5) << "3 scans and 2 edits";
  EXPECT_EQ(start_identity(cfg), a) << "a clean restart continues the saved history";
  const Identity b = run_server(cfg, 3, 2);
  EXPECT_EQ(b.epoch, a.epoch);
  EXPECT_EQ(b.state_id, 7);
  fs::remove_all(dir);
}

TEST(MapIdentity, AResetForksTheHistoryAndTheForkIsPersisted) {
  const auto dir = temp_dir("identity-reset");
  const auto cfg = config_at(dir + "/map.ot");
  const Identity a = run_server(cfg, 0, 2);
  const Identity b = run_server(cfg, 2, 1, 0, /*reset=*/true);
  EXPECT_NE(b.epoch, a.epoch);
  EXPECT_EQ(b.state_id, a.state_id + 2) << "a scan, then the reset: the id never goes back";
  EXPECT_EQ(start_identity(cfg), b);
  fs::remove_all(dir);
}

// What a crash leaves: the files as a running server has them after a periodic save (its
// identity says "unclean"). A server started on them must not reuse ids the dead one may
// have announced after that save.
TEST(MapIdentity, ACrashAfterAPeriodicSaveStartsANewEpoch) {
  const auto dir = temp_dir("identity-crash");
  auto cfg = config_at(dir + "/map.ot");
  const Identity first = run_server(cfg, 0, 2);
  cfg.save_interval_s = 0.1;
  fs::create_directories(dir + "/crashed");
  Identity running;
  {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    daemon::MappingServer server(cfg, lc, log);
    server.start();
    const auto s = wall_scan(2);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
    ASSERT_TRUE(wait_until_done(server, 1));
    for (int i = 0; i < 200 && server.status().map_saves < 1; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_GE(server.status().map_saves, 1);
    running = identity_of(server);
    for (const char* f : {"map.ot", "map.ot.order", "map.ot.identity"})
      fs::copy_file(dir + "/" + f, dir + "/crashed/" + f, fs::copy_options::overwrite_existing);
    server.stop();
  }
  EXPECT_EQ(running.epoch, first.epoch);
  for (const char* f : {"map.ot", "map.ot.order", "map.ot.identity"})
    fs::copy_file(dir + "/crashed/" + f, dir + "/" + f, fs::copy_options::overwrite_existing);
  const Identity after = start_identity(cfg);
  EXPECT_NE(after.epoch, first.epoch);
  EXPECT_EQ(after.state_id, running.state_id) << "the id goes on from the save, in the new epoch";
  fs::remove_all(dir);
}

TEST(MapIdentity, AReplacedCopiedOrOldMapFileStartsANewEpoch) {
  const auto dir = temp_dir("identity-replaced");
  const auto cfg = config_at(dir + "/map.ot");
  const auto other_cfg = config_at(dir + "/other.ot");
  const Identity a = run_server(cfg, 0, 2);
  run_server(other_cfg, 0, 3);
  // Replaced behind the server's back: another map under the same name, the old identity.
  fs::copy_file(dir + "/other.ot", dir + "/map.ot", fs::copy_options::overwrite_existing);
  const Identity replaced = start_identity(cfg);
  EXPECT_NE(replaced.epoch, a.epoch);
  EXPECT_GE(replaced.state_id, a.state_id);
  // A copy of map and identity at another path: a new history there (the original may go on).
  const Identity original = run_server(cfg, 0, 1);
  const auto copy_cfg = config_at(dir + "/copy/map.ot");
  fs::create_directories(dir + "/copy");
  for (const char* f : {"map.ot", "map.ot.order", "map.ot.identity"}) fs::copy_file(dir + "/" + f, dir + "/copy/" + f);
  EXPECT_NE(start_identity(copy_cfg).epoch, original.epoch);
  EXPECT_EQ(start_identity(cfg), original);
  // A map from an older server (no identity file): a new history, the id from its order file.
  fs::remove(dir + "/map.ot.identity");
  const Identity old = start_identity(cfg);
  EXPECT_NE(old.epoch, original.epoch);
  EXPECT_EQ(old.state_id, 3) << "the order file's scans";
  fs::remove_all(dir);
}

TEST(MapIdentity, TheRuleOnItsOwn) {
  daemon::MapIdentityRecord saved{0x1234, 40, 1000, 0xabc, 30, true, "/maps/a.ot"};
  std::istringstream text(daemon::format_map_identity(saved));
  EXPECT_EQ(daemon::parse_map_identity(text), saved);
  const auto at = [&](const std::optional<daemon::MapIdentityRecord>& r, uint64_t bytes, uint64_t hash,
                      const std::string& path) { return daemon::identity_at_load(r, bytes, hash, path, 30, 0x999); };
  EXPECT_TRUE(at(saved, 1000, 0xabc, "/maps/a.ot").continued);
  EXPECT_EQ(at(saved, 1000, 0xabc, "/maps/a.ot").epoch, 0x1234u);
  EXPECT_EQ(at(saved, 1001, 0xabc, "/maps/a.ot").epoch, 0x999u);
  EXPECT_EQ(at(saved, 1000, 0xabd, "/maps/a.ot").epoch, 0x999u);
  EXPECT_EQ(at(saved, 1000, 0xabc, "/maps/b.ot").epoch, 0x999u);
  EXPECT_EQ(at(std::nullopt, 1000, 0xabc, "/maps/a.ot").state_id, 30u);
  auto unclean = saved;
  unclean.clean = false;
  const auto u = at(unclean, 1000, 0xabc, "/maps/a.ot");
  EXPECT_FALSE(u.continued);
  EXPECT_EQ(u.state_id, 40u) << "never back";
  std::istringstream missing("# octomap-rt map identity v1\nepoch 12\n");
  EXPECT_THROW(daemon::parse_map_identity(missing), std::runtime_error);
  std::istringstream bad("epoch zz\nstate_id 1\nmap_bytes 1\nmap_hash 1\norder_entries 1\nclean 1\n");
  EXPECT_THROW(daemon::parse_map_identity(bad), std::runtime_error);
}

TEST(MapFileLock, ASecondServerOnTheSameMapIsRefusedSayingWhoHoldsIt) {
  const auto dir = temp_dir("map-lock");
  const auto cfg = config_at(dir + "/map.ot");
  {
    lcm::LCM lc("memq://");
    std::ostringstream log;
    daemon::MappingServer first(cfg, lc, log);
    try {
      lcm::LCM lc2("memq://");
      daemon::MappingServer second(cfg, lc2, log);
      FAIL() << "two servers on one map file";
    } catch (const daemon::MapStoreError& e) {
      EXPECT_EQ(e.kind(), daemon::MapStoreError::Kind::kLocked);
      const std::string what = e.what();
      EXPECT_NE(what.find("in use by pid " + std::to_string(::getpid())), std::string::npos) << what;
      EXPECT_NE(what.find("test-server"), std::string::npos) << what;
    }
  }
  // Released with the first server: the next one starts.
  lcm::LCM lc("memq://");
  std::ostringstream log;
  EXPECT_NO_THROW(daemon::MappingServer again(cfg, lc, log));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
