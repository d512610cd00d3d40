// The map protocol's constants: channels, sizes, pacing defaults (docs/PROTOCOL.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "octomap_rt/wire_contract.hpp"

namespace ort::protocol {

// Channel names are the wire contract's (spelled once, beside the message types).
inline constexpr const char* kMapRequestChannel = octomap_rt::wire::kMapRequestChannel;
inline constexpr const char* kMapInfoChannel = octomap_rt::wire::kMapInfoChannel;
inline constexpr const char* kMapDeltaChannel = octomap_rt::wire::kMapDeltaChannel;
inline constexpr const char* kMapReplyPrefix = octomap_rt::wire::kMapReplyPrefix;

// One LCM message that fits one UDP datagram: LCM's small-message path is a single
// datagram up to 64 KB; 60 KB leaves room for the header and keeps clear of fragmentation.
inline constexpr size_t kMaxMessageBytes = 60000;
// Payload per snapshot chunk / delta part: the message header and strings fit in the rest.
inline constexpr size_t kChunkDataBytes = 57344;
inline constexpr size_t kDeltaDataBytes = 57344;
// A request may name at most this many chunk indices (a larger list is refused).
inline constexpr int32_t kMaxRequestedChunks = 8192;
// Ids and channel names: [A-Za-z0-9_-], at most this long.
inline constexpr size_t kMaxNameLength = 63;

// Pre-decode byte offsets of each type's variable-length count (fingerprint included),
// checked against real encodings by tests/protocol.
inline constexpr size_t kChunkDataSizeOffset = 86;
inline constexpr size_t kDeltaDataSizeOffset = 74;
inline constexpr size_t kRequestNumIndicesOffset = 33;
inline constexpr size_t kInfoNumProducersOffset = 194;

// FNV-1a, 64 bit: cheap, no dependency, good enough to catch a wrongly assembled blob
// (not an integrity check against an attacker).
inline int64_t blob_hash(const void* data, size_t size) {
  uint64_t h = 1469598103934665603ull;
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return static_cast<int64_t>(h);
}

// 1..kMaxNameLength characters of [A-Za-z0-9_-].
bool valid_name(std::string_view s);
// A client's reply channel: OCTOMAP_RT_MAP_REPLY_<valid name>.
std::string reply_channel_for(std::string_view client_id);

}  // namespace ort::protocol
