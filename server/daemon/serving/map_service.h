// The map service: answers map_request_t on OCTOMAP_RT_MAP_REQUEST with the chunks of a
// snapshot (or only the chunks named, for re-sends), paced so that a client with the
// default socket receive buffer keeps up, and announces the map on OCTOMAP_RT_MAP_INFO at
// 1 Hz and after each new snapshot (docs/PROTOCOL.md).
//
// Threads: its handler on the LCM loop only checks and queues a request (bounded in all and
// per client; a flood is counted as busy, the reply saying when to retry); the service's own
// thread takes snapshots (copy under the map lock, serialize and compress outside it), sends
// the paced chunks (each requested chunk once) and the info messages. Fresh requests share
// one snapshot per fresh_interval_s and wait for it without holding up the others.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "core/log.h"
#include "daemon/map/map_state.h"
#include "daemon/serving/snapshot_store.h"
#include "daemon/transport/lcm_loop.h"
#include "octomap_rt/map_request_t.hpp"
#include "protocol/channels.h"
#include "protocol/map_request_rules.h"
#include "protocol/shards/shard_set.h"

namespace ort::daemon {

struct MapServiceConfig {
  std::string request_channel = ort::protocol::kMapRequestChannel;
  std::string info_channel = ort::protocol::kMapInfoChannel;
  // Replies go only to channels of this prefix + a client id (the namespace's).
  std::string reply_prefix = ort::protocol::kMapReplyPrefix;
  SnapshotPolicy snapshots;
  double chunk_interval_ms = 1.5;  // between two chunks sent (pacing)
  double info_period_s = 1.0;
  size_t request_queue = 256;      // requests waiting, all clients; more are refused as busy
  size_t requests_per_client = 2;  // requests of one client waiting; more are refused as busy
  // Fresh snapshots (snapshot_id < 0) for a flood of requests: at most one per this interval
  // (each copies the map under its lock); every fresh request waiting then gets that one.
  double fresh_interval_s = 2.0;
  std::string server_id, map_frame = "map";
  double resolution = 0;
  double region_min[3] = {0, 0, 0}, region_max[3] = {0, 0, 0};  // set by the server
  protocol::ShardSet shard;                                     // announced in every map_info_t
};

struct MapServiceStats {
  int64_t requests_served = 0, requests_rejected = 0, snapshots_taken = 0, chunks_sent = 0;
  int64_t latest_snapshot_id = -1;
  std::array<int64_t, protocol::kRequestRefusalCount> refusals{};
  double last_copy_lock_ms = 0, max_copy_lock_ms = 0, last_serialize_ms = 0, last_compress_ms = 0;
  int64_t last_raw_size = 0, last_size = 0;
};

class MapService {
 public:
  // `last_delta_seq` (may be empty) tells map_info_t the newest delta sent.
  MapService(LcmLoop& loop, MapState& map, MapServiceConfig cfg, std::function<int64_t()> last_delta_seq, Log log);
  ~MapService();
  MapService(const MapService&) = delete;
  MapService& operator=(const MapService&) = delete;

  void open();   // subscribes on the loop (before it starts)
  void start();  // the service's thread
  void stop();   // unsubscribes, ends the thread (queued requests are dropped). Idempotent.
  MapServiceStats stats() const;

 private:
  void on_request(const lcm::ReceiveBuffer& rbuf);
  void run();
  void serve(const protocol::QueuedMapRequest& queued);
  protocol::SnapshotClock snapshot_clock();
  void refuse(const octomap_rt::map_request_t* req, protocol::RequestRefusal why, const std::string& detail);
  void send_chunks(const octomap_rt::map_request_t& req, const SnapshotBlob& blob);
  void publish_info();
  void note_blob(const SnapshotBlob& b);

  LcmLoop& loop_;
  MapState& map_;
  MapServiceConfig cfg_;
  std::function<int64_t()> last_delta_seq_;
  Log log_;
  SnapshotStore store_;
  LcmLoop::SubscriptionId sub_ = 0;

  mutable std::mutex mutex_;  // queue_, stop_, stats_
  std::condition_variable cv_;
  std::deque<protocol::QueuedMapRequest> queue_;
  bool stop_ = false;
  MapServiceStats stats_;
  std::thread thread_;
};

}  // namespace ort::daemon
