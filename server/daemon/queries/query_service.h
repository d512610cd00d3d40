// The query service: planners' occupancy queries (points, rays, boxes, regions, 2D grids)
// and map edits over LCM, answered on the server from one consistent map state.
//
// LCM thread (handlers on the server's LcmLoop): wire bounds before decode, decode, checks;
// a query that names a usable client and reply channel and fails a check gets a
// BAD_REQUEST reply saying why; one that does not is dropped; both are counted. Valid
// queries go to their client's bounded queue (full: BUSY reply). Edits must carry the MAC of
// --control-token (EditGate: also the time window and a new nonce) and are queued into the
// scan pipeline, so they apply in order with the scans; each is acked and audited.
//
// Worker thread: clients in turn; a query waits (parked, up to its timeout) until the map
// state is >= min_snapshot_id and the robot's wait_seq was applied (read-your-writes), then
// is answered under a shared map lock, with every other query ready then (a turn of at most
// 10 ms: stage 2 may be waiting; each query within its own bounds, QueryBounds, checked
// inside its walk), and its replies are published after the lock, each naming
// the map state (snapshot_id = MapState::version). While stage 2 holds the map for a scan's
// update, a turn reads the read replica instead when it is free and not older than the
// state the worker answered from last (a state between two whole scans too, named by its id).
// With --grid-rate, its GridPublisher also publishes the 2D grid on OCTOMAP_RT_GRID.
// Distance queries read their grid under the lock and run the EDT after it
// (daemon/queries/distance_answers.h), on CPU threads or the Vulkan device (--distance-backend).
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/log.h"
#include "daemon/intake/scan_queue.h"
#include "daemon/map/map_state.h"
#include "daemon/queries/distance_answers.h"
#include "daemon/queries/edit_audit.h"
#include "daemon/queries/edit_gate.h"
#include "daemon/queries/grid_publisher.h"
#include "daemon/queries/query_answers.h"
#include "daemon/queries/query_clients.h"
#include "daemon/queries/query_config.h"
#include "daemon/transport/lcm_loop.h"
#include "protocol/wire_layout.h"

namespace ort::daemon {

class QueryService {
 public:
  // `log` gets one audit line per map edit (who, what, box, result).
  QueryService(const QueryServiceConfig& cfg, MapState& map, ScanQueue& scans, LcmLoop& loop, std::string server_id,
               double resolution, Log log = {});
  ~QueryService();
  // Subscribes (call before the loop starts), then start() the worker (and the grid
  // publisher); stop() joins them.
  void open();
  void start();
  void stop();
  // The server is stopping: the query under the lock now, and every later one, is cut at
  // once (CUT_STOPPING), so that no query holds the map past the drain bound.
  void cut_running();
  std::vector<QueryClientStats> stats() const { return clients_.snapshot(); }
  // Where distance transforms run: "cpu (N threads)" or "vulkan (DEVICE)".
  const std::string& distance_backend() const { return distance_backend_; }
  QueryServiceStats service_stats() const;

 private:
  template <class Message>
  void on_query(const lcm::ReceiveBuffer& rb, protocol::WireCheck (*check)(const uint8_t*, size_t));
  void on_edit(const lcm::ReceiveBuffer& rb, const std::string& channel);
  // "" when client_id and reply_channel are usable for a reply.
  std::string check_addressing(const std::string& client, const std::string& channel) const;
  void run();
  // Under the lock (shared) of the turn's map state (turn_map_): true when answered or refused
  // for good, its replies added to `out` (published after the lock is released); false: not
  // ready yet, within its deadline (or past it on the read replica: the map of record decides).
  bool answer_locked(PendingQuery& q, std::vector<EncodedReplies>& out);
  void answer_restoring(std::vector<PendingQuery>& parked, std::vector<EncodedReplies>& out);
  void publish(const EncodedReplies& r);

  QueryServiceConfig cfg_;
  MapState& map_;
  ScanQueue& scans_;
  LcmLoop& loop_;
  std::string server_id_;
  double resolution_;
  EditAudit audit_;
  QueryClients clients_;
  EditGate gate_;  // the LCM thread's: MAC, time window, nonces
  std::vector<LcmLoop::SubscriptionId> subs_;
  std::thread worker_;
  // Queries of this turn that meet evicted regions, and whether the exclusive turn that
  // answers them is on (the worker's own state).
  std::vector<PendingQuery> to_restore_;
  bool exclusive_turn_ = false;
  // What a turn reads: the map of record, or the read replica while stage 2 holds the map
  // (lock_for_short_read, daemon/map/map_replica.h); the newest state each client was
  // answered from is kept per client (QueryClients::newest_answered).
  MapState* turn_map_ = nullptr;
  GridPublisher grids_;
  distance::SquaredEdt edt_;          // CPU threads or the device; used by the worker thread only
  distance::FieldCache field_cache_;  // the last distance field (distance/field_cache.h); the worker's
  mutable std::mutex field_cache_stats_mutex_;
  distance::FieldCacheStats field_cache_stats_;  // a copy of field_cache_'s, for the status
  std::string distance_backend_;
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::atomic<bool> cut_now_{false};
  std::atomic<int64_t> turns_deferred_{0};  // QueryServiceStats::turns_deferred
};

}  // namespace ort::daemon
