// The protocol version (docs/PROTOCOL.md, "Versions"): one step per release that changes any
// message, channel or limit. The server sends it as the first field of map_info_t and
// server_status_t, and it stays their first field in every version, so a client that gets a
// fingerprint it does not know can still read which version the server speaks and say so.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace ort::protocol {

inline constexpr int32_t kProtocolVersion = 3;

// For a map_info_t or server_status_t message whose 8-byte fingerprint is not
// `expected_hash`: what its sender speaks, in words ("the server speaks protocol version 3,
// this program version 2: ..."); "" when the fingerprint is ours (or the bytes too short).
std::string describe_foreign_version(const uint8_t* data, size_t size, int64_t expected_hash);

}  // namespace ort::protocol
