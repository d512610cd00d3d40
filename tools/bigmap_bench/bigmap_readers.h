// The readers of the big-map benchmark, each on its own thread against an in-process server
// on a shared memq:// LCM: a client pulling fresh snapshots at a period, and query clients
// (each its own client id, so the server keeps a newest answered state per client) sending
// point queries at a share of the rate. Replies come through the server's own LCM loop (on a shared
// memq:// instance only the server's thread may call handle).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/clock.h"
#include "daemon/mapping_server.h"

namespace ort::bench {

struct ReaderStats {
  int64_t snapshots = 0, snapshot_timeouts = 0;  // timeouts: not whole in 120 s, or refused
  std::string snapshot_error;                    // the server's last refusal, if any
  double snapshot_s_max = 0, snapshot_s_sum = 0;
  int64_t snapshot_bytes = 0;
  std::vector<double> query_ms;  // one per answered query
  int64_t queries_sent = 0, queries_unanswered = 0;
  int64_t queries_not_ok = 0;  // answered with a status other than REPLY_OK (cut, refused): not in query_ms
};

class BenchReaders {
 public:
  // box: the map's extent, where query points are drawn. query_clients: how many clients share
  // query_rate_hz (at least 1).
  BenchReaders(daemon::MappingServer& server, lcm::LCM& lc, double snapshot_period_s, double query_rate_hz,
               int query_clients, const double box_min[3], const double box_max[3]);
  ~BenchReaders();
  void start();
  void stop();
  ReaderStats stats();

 private:
  void pull_snapshots();
  void send_queries(int client);

  daemon::MappingServer& server_;
  lcm::LCM& lc_;
  double snapshot_period_s_, query_rate_hz_;
  int query_clients_;
  double box_min_[3], box_max_[3];
  std::atomic<bool> stop_{false};
  std::thread snapshots_;
  std::vector<std::thread> queries_;       // one per query client
  std::atomic<int64_t> next_query_id_{0};  // unique across clients: replies are matched by id
  std::mutex mutex_;                       // everything below
  ReaderStats stats_;
  int64_t chunk_request_ = -1;
  int32_t chunks_expected_ = -1, chunks_got_ = 0;
  std::vector<std::pair<int64_t, SteadyClock::time_point>> in_flight_;  // query id, sent
};

}  // namespace ort::bench
