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
#include <utility>
#include <variant>
#include <vector>

#include "core/clock.h"
#include "distance/field_cache.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"

namespace ort::daemon {

using QueryMessage = std::variant<octomap_rt::occupancy_query_t, octomap_rt::ray_query_t, octomap_rt::box_query_t,
                                  octomap_rt::grid_query_t, octomap_rt::distance_query_t>;

struct PendingQuery {
  QueryMessage msg;
  SteadyClock::time_point received, deadline;  // deadline: when waiting for the map state ends
};

struct QueryClientStats {
  std::string client_id;  // "?": messages that named no usable client
  int64_t received = 0, answered = 0, bad = 0, busy = 0, not_ready = 0, dropped = 0;
  int64_t cut = 0;  // answered in part: past a bound (also counted in answered)
  int64_t edits_applied = 0, edits_refused = 0;
  int64_t last_utime = 0;     // when its last message arrived [us since the epoch]
  int64_t queue_depth = 0;    // queued now (filled by snapshot())
  std::string reply_channel;  // of its last message
  std::string last_error;
};

// What the status reports of the query service.
struct QueryServiceStats {
  std::vector<QueryClientStats> clients;
  // Why messages were refused (bad, busy, not ready, dropped, edits refused), digits as '#'
  // so that "depth 17 ..." and "depth 20 ..." count as one reason; at most kMaxReasons.
  std::vector<std::pair<std::string, int64_t>> refusal_reasons;
  int64_t grids_published = 0;
  // Query turns that found neither the map of record free nor the read replica new enough for
  // the clients waiting then, and so asked again (stage 2 held the map meanwhile).
  int64_t turns_deferred = 0;
  distance::FieldCacheStats field_cache;  // the distance field cache's updates (distance/field_cache.h)
};

class QueryClients {
 public:
  // With max_clients named clients tracked, a new one takes the slot of the one heard from
  // least recently if that one has been idle (nothing queued) for idle_expiry_us: its
  // counters are folded into client "~" so that the totals still add up. Otherwise new
  // clients share "*".
  QueryClients(size_t per_client_queue, size_t max_clients, int64_t idle_expiry_us = int64_t(600) * 1'000'000);
  // Queues q for its client; false (counted busy) when that client's queue is full.
  bool push(const std::string& client, PendingQuery&& q);
  // The next query, clients taken in turn, of a client whose newest answered map state is
  // `state` or older (a turn on an older read replica leaves the others queued); nullopt
  // when none is queued.
  std::optional<PendingQuery> pop(uint64_t state = UINT64_MAX);
  // Per client: the newest map state id it was answered from (answers never go back for it).
  void answered_at(const std::string& client, uint64_t state);
  uint64_t newest_answered(const std::string& client);
  // The oldest of newest_answered over the clients with queued queries (UINT64_MAX: none).
  uint64_t oldest_answered_queued() const;
  size_t queued() const;

  // A message with a usable address arrived from `client`, to be answered on `reply_channel`.
  void received(const std::string& client, const std::string& reply_channel, int64_t utime);
  // kAnsweredCut: answered in part (past a bound); counts as answered and as cut, its
  // error is a reason.
  enum class Count { kAnswered, kAnsweredCut, kBad, kBusy, kNotReady, kDropped, kEditApplied, kEditRefused };
  // `error` says why (refusals); it becomes the client's last_error and a refusal reason.
  void count(const std::string& client, Count what, const std::string& error = "");
  std::vector<QueryClientStats> snapshot() const;
  std::vector<std::pair<std::string, int64_t>> refusal_reasons() const;
  static constexpr size_t kMaxReasons = 32;  // more distinct reasons are counted under "other"

 private:
  struct Client {
    QueryClientStats stats;
    std::deque<PendingQuery> queue;
    uint64_t newest_state = 0;
  };
  Client& at(const std::string& client);                                 // under mutex_
  size_t named_clients() const;                                          // under mutex_
  void expire_idle(int64_t now_us);                                      // under mutex_
  void bump(QueryClientStats& s, Count what, const std::string& error);  // under mutex_

  mutable std::mutex mutex_;
  size_t per_client_queue_, max_clients_;
  int64_t idle_expiry_us_;
  std::map<std::string, Client> clients_;
  std::string next_;  // round-robin position: first client after this name
  size_t queued_ = 0;
  std::map<std::string, int64_t> reasons_;
};

// The end-of-run lines of the query service (one per client; nothing without queries).
void print_query_summary(std::ostream& out, const std::vector<QueryClientStats>& clients);

}  // namespace ort::daemon
