// Per-client bookkeeping of the query service: a bounded queue per client (a flooding
// client gets BUSY replies and cannot delay the others: the worker takes clients in turn)
// and counters per client, for the status and the summary.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "daemon/scan_queue.h"  // Clock
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"

namespace ort::daemon {

using QueryMessage =
    std::variant<octomap_rt::occupancy_query_t, octomap_rt::ray_query_t, octomap_rt::box_query_t, octomap_rt::grid_query_t>;

struct PendingQuery {
  QueryMessage msg;
  Clock::time_point received, deadline;  // deadline: when waiting for the map state ends
};

struct QueryClientStats {
  std::string client_id;                 // "?": messages that named no usable client
  int64_t received = 0, answered = 0, bad = 0, busy = 0, not_ready = 0, dropped = 0;
  int64_t edits_applied = 0, edits_refused = 0;
  std::string last_error;
};

class QueryClients {
 public:
  QueryClients(size_t per_client_queue, size_t max_clients);
  // Queues q for its client; false (counted busy) when that client's queue is full.
  bool push(const std::string& client, PendingQuery&& q);
  // The next query, clients taken in turn; nullopt when none is queued.
  std::optional<PendingQuery> pop();
  size_t queued() const;

  enum class Count { kReceived, kAnswered, kBad, kBusy, kNotReady, kDropped, kEditApplied, kEditRefused };
  void count(const std::string& client, Count what, const std::string& error = "");
  std::vector<QueryClientStats> snapshot() const;

 private:
  struct Client {
    QueryClientStats stats;
    std::deque<PendingQuery> queue;
  };
  Client& at(const std::string& client);  // under mutex_

  mutable std::mutex mutex_;
  size_t per_client_queue_, max_clients_;
  std::map<std::string, Client> clients_;
  std::string next_;                     // round-robin position: first client after this name
  size_t queued_ = 0;
};

// The end-of-run lines of the query service (one per client; nothing without queries).
void print_query_summary(std::ostream& out, const std::vector<QueryClientStats>& clients);

}  // namespace ort::daemon
