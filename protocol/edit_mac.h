// The authentication of map edits (map_edit_t.mac): HMAC-SHA256, keyed by the server's control
// token, of the edit's canonical bytes, so that an edit proves its sender holds the token
// without sending it. The server also refuses an edit outside its time window or with a nonce
// it has seen (daemon/queries/edit_gate.h): a MAC alone does not stop a replay.
//
// The canonical bytes (docs/PROTOCOL.md, "Authenticated edits"; the Python and Java clients
// build the same bytes), all integers big-endian:
//   "octomap-rt map_edit_t v1" and one 0 byte (25 bytes: the domain of this MAC),
//   the channel the edit is published on, then utime, request_id, nonce (int64 each), op,
//   flags (int8 each), box_min[0..2], box_max[0..2] (IEEE-754 binary64 each), client_id,
//   reply_channel; each string as its length (uint32) and its bytes, without a NUL.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "octomap_rt/map_edit_t.hpp"

namespace ort::protocol {

using EditMac = std::array<uint8_t, 32>;

std::vector<uint8_t> edit_mac_input(std::string_view channel, const octomap_rt::map_edit_t& edit);
EditMac edit_mac(std::string_view token, std::string_view channel, const octomap_rt::map_edit_t& edit);
// Whether edit.mac is the edit's MAC under `token` (compared in constant time).
bool edit_mac_matches(std::string_view token, std::string_view channel, const octomap_rt::map_edit_t& edit);
// Sets edit.mac (after every other field is final).
void sign_edit(octomap_rt::map_edit_t& edit, std::string_view token, std::string_view channel);

// A fresh random nonce for an edit (the operating system's generator).
int64_t random_edit_nonce();

}  // namespace ort::protocol
