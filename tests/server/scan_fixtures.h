// What the daemon's in-process tests share: scan_t messages made from posed scans (as a
// producer makes them), raw encodings to corrupt, a server config for memq://, waiting for
// the server to finish, and reference maps built in a given order.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <octomap/OcTree.h>

#include "daemon/map/applied_order.h"
#include "daemon/mapping_server.h"
#include "daemon/server_config.h"
#include "octomap_rt/scan_t.hpp"
#include "scene/scan_set.h"

namespace ort::test {

// Sensor-frame points + pose (the float pose carried exactly in doubles).
octomap_rt::scan_t scan_message(const PosedScan& scan, const std::string& robot_id, int64_t seq);
// A small valid scan: `points` points 2 m in front of a sensor at (1, 2, 0.5).
octomap_rt::scan_t small_scan(const std::string& robot_id, int64_t seq, int points = 30);
// `n` points `distance` metres from a sensor at `at`, in random directions (seeded by seq),
// robot id "alpha": what a scan far-reaching for its size costs (issue 21's far scans).
octomap_rt::scan_t reaching_scan(int64_t seq, const octomap::point3d& at, double distance, int n);
std::vector<uint8_t> encode(const octomap_rt::scan_t& msg);
void put_be32(std::vector<uint8_t>& buf, size_t offset, int32_t v);

// cpu back end, resolution `res`, memq-friendly (no map file unless given).
daemon::ServerConfig test_config(double res, bool pipelined);

// Polls until every producer's messages are all received (sum = `messages`) and none is in
// flight; false on timeout.
bool wait_until_done(daemon::MappingServer& server, int64_t messages,
                     std::chrono::seconds timeout = std::chrono::seconds(120));

// Every producer: received = applied + rejected + dropped (nothing in flight).
void expect_counts_balance(const std::vector<daemon::ProducerStats>& stats);

// MapEngine (same options) applied to `scans` in `order`: the sequential reference.
// `by_robot_seq(robot_id, seq)` returns the scan that (robot, seq) names.
std::unique_ptr<octomap::OcTree> engine_reference(
    const daemon::ServerConfig& cfg, const std::vector<daemon::AppliedEntry>& order,
    const std::function<const PosedScan&(const std::string&, int64_t)>& by_robot_seq);

std::string temp_dir(const std::string& tag);

// Holds the server's map lock (a reader in with_map) on a thread of its own from construction
// until release() or destruction: stage 2 cannot apply, so scans and edits stay queued.
// Construct it after server.start(); it returns once the lock is held.
// A server over its own memq:// instance, started with `cfg`, its log kept.
struct MemqServer {
  lcm::LCM lc{"memq://"};
  std::ostringstream log;
  daemon::MappingServer server;
  explicit MemqServer(const daemon::ServerConfig& cfg) : server(cfg, lc, log) { server.start(); }
};

class MapHold {
 public:
  explicit MapHold(daemon::MappingServer& server);
  ~MapHold() { release(); }
  MapHold(const MapHold&) = delete;
  MapHold& operator=(const MapHold&) = delete;
  // Lets the map go and joins the holding thread. Idempotent.
  void release();

 private:
  std::mutex m_;
  std::condition_variable cv_;
  bool holding_ = false, release_ = false;
  std::thread holder_;
};

}  // namespace ort::test
