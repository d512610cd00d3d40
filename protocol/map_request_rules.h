// What the map service accepts in a decoded map_request_t, and why it refuses the rest.
#pragma once

#include <cstdint>
#include <string>

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
  kCount
};
inline constexpr size_t kRequestRefusalCount = static_cast<size_t>(RequestRefusal::kCount);

const char* to_string(RequestRefusal r);

// Checks what can be checked without the snapshot: names, format, indices.
RequestRefusal check_map_request(const octomap_rt::map_request_t& r);
// Whether a refusal can be answered (the reply channel is usable).
bool can_reply(const octomap_rt::map_request_t& r);

}  // namespace ort::protocol
