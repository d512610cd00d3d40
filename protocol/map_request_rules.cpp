#include "protocol/map_request_rules.h"

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
    case RequestRefusal::kCount: break;
  }
  return "?";
}

bool can_reply(const octomap_rt::map_request_t& r) {
  const std::string prefix = kMapReplyPrefix;
  return r.reply_channel.size() > prefix.size() && r.reply_channel.compare(0, prefix.size(), prefix) == 0 &&
         valid_name(r.reply_channel);
}

RequestRefusal check_map_request(const octomap_rt::map_request_t& r) {
  using Chunk = octomap_rt::map_chunk_t;
  if (!valid_name(r.client_id)) return RequestRefusal::kBadClientId;
  if (!can_reply(r)) return RequestRefusal::kBadReplyChannel;
  if (r.format != Chunk::FORMAT_OCTOMAP_BINARY && r.format != Chunk::FORMAT_OCTOMAP_FULL)
    return RequestRefusal::kUnknownFormat;
  for (int32_t i : r.chunk_indices)
    if (i < 0) return RequestRefusal::kBadChunkIndex;
  return RequestRefusal::kNone;
}

}  // namespace ort::protocol
