// A load test of octomap-rt-server (issue 13): N producers publish synthetic scans at a rate
// for a bounded time over udpm inside a private network namespace, while the server's status
// is decoded; the report says whether every scan is accounted for, the server's peak memory,
// its end-to-end latency p99 and what was dropped or rejected and why.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace ort::cli {

struct LoadTestConfig {
  std::string server;                                    // octomap-rt-server program
  std::vector<std::string> server_args = {"-r", "0.1"};  // besides --lcm-url
  int producers = 4;
  double rate_hz = 5;  // per producer
  double duration_s = 20;
  int points = 20'000;    // per scan (a ring of range readings from the synthetic scene's poses)
  int port = 7667;        // udpm port inside the namespace
  double settle_s = 120;  // after publishing stops, wait this long for the queue to empty
  std::string log_path = "loadtest-server.log";
  // What the robots scan: "synthetic" (the built-in rooms), a preset name (fr079-real, ...;
  // scene/scene_presets.h) or a ScanGraph .graph file. Each producer goes round its poses
  // again and again (robots circling the scene), from its own start.
  std::string scene = "synthetic";
  std::string data_dir;  // where fr079-real finds geb079.bt
  // A CSV line per status message (the soak benchmark's time series): seconds since the
  // publishing began, the server's RSS and peak RSS, its map memory and nodes, end-to-end
  // p99, scans applied. "": none.
  std::string series_path;
};

struct LoadReport {
  int64_t published = 0, publish_errors = 0;
  int64_t received = 0, applied = 0, rejected = 0, dropped = 0, in_flight = 0, missed = 0;
  std::map<std::string, int64_t> drop_reasons, reject_reasons;
  int64_t kernel_drops = -1;  // the server's own socket (RcvbufErrors), -1: unknown
  double peak_rss_mib = 0;    // the server's VmHWM
  double e2e_p99_ms_max = 0;  // largest p99 over the status messages of the run
  double e2e_p99_ms_last = 0;
  double scans_per_s = 0;  // applied / duration
  int64_t degraded_statuses = 0, statuses = 0;
  std::string last_message;
  int server_exit = -1;
  bool accounted() const { return received == applied + rejected + dropped && in_flight == 0; }
};

// Must run in a network namespace of its own (see enter_private_network): publishes on
// udpm://239.255.76.67:<port>?ttl=0. Throws std::runtime_error when the server cannot start.
LoadReport run_load_test(const LoadTestConfig& cfg);

// Moves this (single-threaded) process into new user + network namespaces with loopback up
// and a multicast route, so nothing leaves it. Returns "" or why it failed.
std::string enter_private_network();

void print_load_report(std::ostream& out, const LoadTestConfig& cfg, const LoadReport& r);

}  // namespace ort::cli
