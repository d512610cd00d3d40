// What the map service accepts in a decoded map_request_t, and why it refuses the rest.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "core/clock.h"
#include "octomap_rt/map_request_t.hpp"

namespace ort::protocol {

enum class RequestRefusal : uint8_t {
  kNone,
  kUndecodable,      // failed the pre-decode checks (no reply possible)
  kBadClientId,      // not 1..63 of [A-Za-z0-9_-]
  kBadReplyChannel,  // not OCTOMAP_RT_MAP_REPLY_<name>
  kUnknownFormat,
  kBadChunkIndex,    // negative index in the list
  kUnknownSnapshot,  // not (or no longer) kept
  kChunkOutOfRange,  // an index >= num_chunks of that snapshot
  kBusy,             // the service's request queue was full
  kClientBusy,       // that client already had MapServiceConfig::requests_per_client queued
  kCount
};
inline constexpr size_t kRequestRefusalCount = static_cast<size_t>(RequestRefusal::kCount);

const char* to_string(RequestRefusal r);

// Checks what can be checked without the snapshot: names, format, indices. `reply_prefix`: the
// server's map reply prefix (its namespace's: protocol::channels_in(ns).map_reply_prefix).
RequestRefusal check_map_request(const octomap_rt::map_request_t& r, const std::string& reply_prefix);
// Whether a refusal can be answered (the reply channel is usable: the prefix and a name).
bool can_reply(const octomap_rt::map_request_t& r, const std::string& reply_prefix);

// The chunks a request makes the server send: each index once, in increasing order (a
// request repeating one index must not make the server send it again and again); all of a
// snapshot of n chunks when it names none.
std::vector<int32_t> chunks_to_send(const std::vector<int32_t>& requested, int32_t n);

// A request waiting in the map service's queue.
struct QueuedMapRequest {
  octomap_rt::map_request_t req;
  SteadyClock::time_point arrived;
};

// What the queue knows of the snapshots when it picks the next request to serve.
struct SnapshotClock {
  SteadyClock::time_point now;
  SteadyClock::time_point newest_taken;  // the newest snapshot's copy; {} = none
  bool newest_is_current = false;        // the map did not change since
  SteadyClock::duration fresh_interval{};
};

// The request to serve next, or SIZE_MAX: the oldest that can be served now. A fresh one
// (snapshot_id < 0) can when a snapshot newer than its arrival exists (one taken for another
// fresh request serves them all) or may be taken now (at most one per fresh_interval);
// until then it waits without holding up the others.
size_t next_servable(const std::deque<QueuedMapRequest>& queue, const SnapshotClock& clock);
// When the first waiting fresh request becomes servable (time_point::max() when none waits).
SteadyClock::time_point next_fresh_due(const std::deque<QueuedMapRequest>& queue, const SnapshotClock& clock);
// How many requests of `client_id` are queued.
size_t queued_of(const std::deque<QueuedMapRequest>& queue, const std::string& client_id);

}  // namespace ort::protocol
