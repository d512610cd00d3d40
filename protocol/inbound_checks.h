// The raw-byte layouts and pre-decode checks of every inbound message: scans, map requests,
// queries and edits (server side), snapshot chunks, deltas and map infos (client side).
//
// LCM 1.3.1's generated decode() trusts every length it reads (protocol/wire_layout.h says
// what goes wrong), so each message is walked by its layout first: its size within its bound,
// the fingerprint, each count within its bound (protocol/limits.h) and backed by bytes, each
// string's length, nothing after the end. One style everywhere: a WireCheck, a typed refusal
// with its reason (describe() for the text a log or a client gets).
#pragma once

#include <cstddef>
#include <cstdint>
#include <exception>

#include "protocol/wire_layout.h"

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_delta_t.hpp"
#include "octomap_rt/map_info_t.hpp"
#include "octomap_rt/map_request_t.hpp"

namespace ort::protocol {

// --- Byte offsets (the 8-byte fingerprint included) ---------------------------------------
// The .lcm files keep only fixed-size fields before their first count, so these are
// constants; tests/protocol checks them against real encodings.
inline constexpr size_t kScanNumXyzOffset = 85;  // scan_t.num_xyz
inline constexpr size_t kScanXyzOffset = 89;     // scan_t.xyz[0]
inline constexpr size_t kChunkDataSizeOffset = 94;
inline constexpr size_t kDeltaDataSizeOffset = 82;
inline constexpr size_t kRequestNumIndicesOffset = 33;
inline constexpr size_t kInfoNumProducersOffset = 216;
// Where protocol_version sits in map_info_t and server_status_t, in every version
// (protocol/version.h).
inline constexpr size_t kVersionOffset = 8;

// --- Server side --------------------------------------------------------------------------
// A scan_t with at most `max_points` points (--max-points).
WireCheck check_scan_bytes(const uint8_t* data, size_t size, uint64_t max_points);
WireCheck check_map_request_bytes(const uint8_t* data, size_t size);
WireCheck check_occupancy_query_bytes(const uint8_t* data, size_t size);
WireCheck check_ray_query_bytes(const uint8_t* data, size_t size);
WireCheck check_box_query_bytes(const uint8_t* data, size_t size);
WireCheck check_grid_query_bytes(const uint8_t* data, size_t size);
WireCheck check_distance_query_bytes(const uint8_t* data, size_t size);
WireCheck check_map_edit_bytes(const uint8_t* data, size_t size);

// --- Client side --------------------------------------------------------------------------
WireCheck check_map_chunk_bytes(const uint8_t* data, size_t size);
WireCheck check_map_delta_bytes(const uint8_t* data, size_t size);
WireCheck check_map_info_bytes(const uint8_t* data, size_t size);

// Runs `check`, then LCM's decode() into `out` (inside try/catch): ok() when `out` holds the
// message, else the first fault.
template <class T>
WireCheck decode_checked(const void* data, size_t size, WireCheck (*check)(const uint8_t*, size_t), T& out) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  if (WireCheck c = check(bytes, size); !c.ok()) return c;
  try {
    const int n = out.decode(data, 0, static_cast<int>(size));
    if (n < 0) return {WireFault::kUndecodable};
    if (static_cast<size_t>(n) != size) return {WireFault::kTrailingBytes};
  } catch (const std::exception&) {
    return {WireFault::kUndecodable};
  }
  return {};
}

// Checked and decoded, for the map protocol's four types.
inline WireCheck check_chunk(const void* d, size_t n, octomap_rt::map_chunk_t& out) {
  return decode_checked(d, n, check_map_chunk_bytes, out);
}
inline WireCheck check_delta(const void* d, size_t n, octomap_rt::map_delta_t& out) {
  return decode_checked(d, n, check_map_delta_bytes, out);
}
inline WireCheck check_info(const void* d, size_t n, octomap_rt::map_info_t& out) {
  return decode_checked(d, n, check_map_info_bytes, out);
}
inline WireCheck check_request(const void* d, size_t n, octomap_rt::map_request_t& out) {
  return decode_checked(d, n, check_map_request_bytes, out);
}

}  // namespace ort::protocol
