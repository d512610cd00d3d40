#include "protocol/map_request_rules.h"

#include <algorithm>

#include "octomap_rt/map_chunk_t.hpp"
#include "protocol/channels.h"
#include "protocol/ids.h"

namespace ort::protocol {

const char* to_string(RequestRefusal r) {
  switch (r) {
    case RequestRefusal::kNone: return "ok";
    case RequestRefusal::kUndecodable: return "undecodable request";
    case RequestRefusal::kBadClientId: return "bad client id";
    case RequestRefusal::kBadReplyChannel: return "bad reply channel";
    case RequestRefusal::kUnknownFormat: return "unknown format";
    case RequestRefusal::kBadChunkIndex: return "negative chunk index";
    case RequestRefusal::kUnknownSnapshot: return "snapshot not kept";
    case RequestRefusal::kChunkOutOfRange: return "chunk index out of range";
    case RequestRefusal::kBusy: return "busy (request queue full)";
    case RequestRefusal::kClientBusy: return "busy (this client's requests are queued)";
    case RequestRefusal::kCount: break;
  }
  return "?";
}

bool can_reply(const octomap_rt::map_request_t& r, const std::string& prefix) {
  return r.reply_channel.size() > prefix.size() && r.reply_channel.compare(0, prefix.size(), prefix) == 0 &&
         valid_name(r.reply_channel);
}

RequestRefusal check_map_request(const octomap_rt::map_request_t& r, const std::string& reply_prefix) {
  using Chunk = octomap_rt::map_chunk_t;
  if (!valid_name(r.client_id)) return RequestRefusal::kBadClientId;
  if (!can_reply(r, reply_prefix)) return RequestRefusal::kBadReplyChannel;
  if (r.format != Chunk::FORMAT_OCTOMAP_BINARY && r.format != Chunk::FORMAT_OCTOMAP_FULL)
    return RequestRefusal::kUnknownFormat;
  for (int32_t i : r.chunk_indices)
    if (i < 0) return RequestRefusal::kBadChunkIndex;
  return RequestRefusal::kNone;
}

std::vector<int32_t> chunks_to_send(const std::vector<int32_t>& requested, int32_t n) {
  std::vector<int32_t> out;
  if (requested.empty()) {
    out.resize(static_cast<size_t>(std::max<int32_t>(0, n)));
    for (int32_t i = 0; i < n; ++i) out[static_cast<size_t>(i)] = i;
    return out;
  }
  out = requested;
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

bool fresh_servable(const QueuedMapRequest& q, const SnapshotClock& c) {
  if (c.newest_is_current) return true;
  if (c.newest_taken == SteadyClock::time_point{}) return true;
  if (c.newest_taken >= q.arrived) return true;
  return c.now >= c.newest_taken + c.fresh_interval;
}

}  // namespace

size_t next_servable(const std::deque<QueuedMapRequest>& queue, const SnapshotClock& clock) {
  for (size_t i = 0; i < queue.size(); ++i)
    if (queue[i].req.snapshot_id >= 0 || fresh_servable(queue[i], clock)) return i;
  return SIZE_MAX;
}

SteadyClock::time_point next_fresh_due(const std::deque<QueuedMapRequest>& queue, const SnapshotClock& clock) {
  for (const QueuedMapRequest& q : queue)
    if (q.req.snapshot_id < 0) return clock.newest_taken + clock.fresh_interval;
  return SteadyClock::time_point::max();
}

size_t queued_of(const std::deque<QueuedMapRequest>& queue, const std::string& client_id) {
  return static_cast<size_t>(std::count_if(queue.begin(), queue.end(),
                                           [&](const QueuedMapRequest& q) { return q.req.client_id == client_id; }));
}

}  // namespace ort::protocol
