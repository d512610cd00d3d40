// A client of octomap-rt-server's map service (docs/PROTOCOL.md): fetches snapshots with
// re-requests of missing chunks, reads map_info_t, and hands map deltas to a handler.
//
// Single-threaded by design: every call runs LCM's handle on the caller's thread (LCM
// allows one handling thread), so a MapClient and the MapMirror on it are used from one
// thread. Every inbound message is checked on its raw bytes before decode
// (protocol/inbound_checks.h); refusals are counted by reason.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <octomap/OcTree.h>
#include <lcm/lcm-cpp.hpp>

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_delta_t.hpp"
#include "octomap_rt/map_info_t.hpp"
#include "protocol/channels.h"

namespace ort::client {

// Why a fetch failed: kTimeout (chunks still missing at the deadline, or no server),
// kRefused (the server answered with an error), kCorrupt (the blob did not check out).
struct FetchError : std::runtime_error {
  enum Kind { kTimeout, kRefused, kCorrupt };
  FetchError(Kind k, const std::string& what) : std::runtime_error(what), kind(k) {}
  Kind kind;
};

struct ClientOptions {
  std::string client_id;            // "": client_<pid>_<random>
  double rerequest_after_s = 0.25;  // silence before missing chunks are asked for again
  double first_answer_after_s = 3;  // silence before a request with no answer at all is repeated
  std::string request_channel = ort::protocol::kMapRequestChannel;
  std::string info_channel = ort::protocol::kMapInfoChannel;
  std::string delta_channel = ort::protocol::kMapDeltaChannel;
  std::string reply_prefix = ort::protocol::kMapReplyPrefix;  // + the client id: the reply channel
  // The four channels above in namespace `ns` (the server's --namespace; "" = today's names).
  // Throws std::invalid_argument for a namespace protocol::channels_in refuses.
  ClientOptions& in_namespace(const std::string& ns) {
    const protocol::Channels c = protocol::channels_in(ns);
    request_channel = c.map_request, info_channel = c.map_info, delta_channel = c.map_delta;
    reply_prefix = c.map_reply_prefix;
    return *this;
  }
  // Test hooks in the receive path, after validation: return true to treat the message as
  // lost on the way (loss tests without netem).
  std::function<bool(const octomap_rt::map_chunk_t&)> drop_chunk;
  std::function<bool(const octomap_rt::map_delta_t&)> drop_delta;
};

struct FetchedSnapshot {
  int64_t snapshot_id = 0, num_scans = 0;
  int64_t map_epoch = 0;  // the history snapshot_id counts in
  int8_t format = 0;
  std::string bytes;  // decompressed: the .bt or .ot file's content
  int64_t compressed_size = 0;
  int32_t num_chunks = 0, requests = 0, chunks_dropped = 0;
  int32_t busy_replies = 0;  // refusals as busy, each followed by a retry after the time it named
  double seconds = 0;
  // Parses bytes (either format). Throws FetchError(kCorrupt) when OctoMap cannot.
  std::unique_ptr<octomap::OcTree> tree() const;
};

// (bytes received, bytes in all) while a fetch runs.
using FetchProgress = std::function<void(int64_t, int64_t)>;

struct InboundCounts {
  std::map<std::string, int64_t> refused;  // reason -> messages
  // Non-empty when a map_info_t came from a server of another protocol version: which
  // (protocol/version.h), said in every timeout's message.
  std::string foreign_version;
  int64_t chunks = 0, infos = 0, deltas = 0;
};

class MapClient {
 public:
  // Own LCM on `url` ("" : LCM's default). Throws std::runtime_error when LCM cannot start.
  explicit MapClient(const std::string& url, ClientOptions opts = {});
  ~MapClient();
  MapClient(const MapClient&) = delete;
  MapClient& operator=(const MapClient&) = delete;

  // A snapshot, fresh (at least as new as the map when the server gets the request) unless
  // `snapshot_id` names a kept one. format: map_chunk_t::FORMAT_*. Throws FetchError.
  FetchedSnapshot fetch_snapshot(int8_t format, double timeout_s, const FetchProgress& progress = {},
                                 int64_t snapshot_id = -1);
  // The next map_info_t (nullopt at the timeout).
  std::optional<octomap_rt::map_info_t> wait_info(double timeout_s);
  // Deltas go to `handler` from now on (subscribes the delta channel).
  void on_delta(std::function<void(const octomap_rt::map_delta_t&)> handler);
  // Every map_info_t received from now on also goes to `handler`.
  void on_info(std::function<void(const octomap_rt::map_info_t&)> handler);
  // Handles inbound messages for up to `timeout_s` (deltas reach their handler).
  void spin(double timeout_s);

  const std::string& client_id() const { return opts_.client_id; }
  const InboundCounts& inbound() const { return inbound_; }
  lcm::LCM& lcm() { return lcm_; }

 private:
  void on_chunk_bytes(const lcm::ReceiveBuffer* rb, const std::string& channel);
  void on_info_bytes(const lcm::ReceiveBuffer* rb, const std::string& channel);
  void on_delta_bytes(const lcm::ReceiveBuffer* rb, const std::string& channel);
  void send_request(int64_t request_id, int64_t snapshot_id, int8_t format, const std::vector<int32_t>& indices);
  void handle_for(double seconds);

  ClientOptions opts_;
  lcm::LCM lcm_;
  std::string reply_channel_;
  int64_t next_request_id_ = 1;
  InboundCounts inbound_;
  std::vector<octomap_rt::map_chunk_t> chunks_;  // received since the last look
  std::optional<octomap_rt::map_info_t> info_;
  std::function<void(const octomap_rt::map_delta_t&)> delta_handler_;
  std::function<void(const octomap_rt::map_info_t&)> info_handler_;
  lcm::Subscription* delta_sub_ = nullptr;
};

}  // namespace ort::client
