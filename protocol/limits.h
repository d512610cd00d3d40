// Every wire limit of the protocol, spelled once (docs/PROTOCOL.md): what one message may
// carry. The server refuses more (a typed refusal, protocol/inbound_checks.h); the clients
// split their requests to stay inside (the Python client's table is checked against this file
// by tests/protocol).
#pragma once

#include <cstddef>
#include <cstdint>

namespace ort::protocol {

// --- Scans --------------------------------------------------------------------------------
// Points in one scan_t the server accepts by default (--max-points); 12 bytes each.
inline constexpr uint64_t kDefaultMaxScanPoints = 4'000'000;
// scan_t.robot_id (and every robot id on the wire): 1-32 of [A-Za-z0-9_-].
inline constexpr size_t kMaxRobotIdLength = 32;
// Smallest positive scan_t.max_range [m] (<= 0 means "no limit of its own"): below it every
// ray ends in the sensor's voxel; the server refuses such a scan ("max range too small").
inline constexpr double kMinScanMaxRange = 1e-3;
// scan_t.map_frame.
inline constexpr size_t kMaxMapFrameLength = 256;

// --- Messages of the map protocol, queries and edits --------------------------------------
// One LCM message that fits one UDP datagram: LCM's small-message path is a single
// datagram up to 64 KB; 60 KB leaves room for the header and keeps clear of fragmentation.
inline constexpr size_t kMaxMessageBytes = 60000;
// The largest query or edit message read at all (a datagram); larger ones are refused unread.
inline constexpr size_t kMaxInboundQueryBytes = 65536;
// Payload per snapshot chunk / delta part: the message header and strings fit in the rest.
inline constexpr size_t kChunkDataBytes = 57344;
inline constexpr size_t kDeltaDataBytes = 57344;
// A map request may name at most this many chunk indices (a larger list is refused).
inline constexpr int32_t kMaxRequestedChunks = 8192;
// Client ids: 1..63 of [A-Za-z0-9_-] (protocol/ids.h); the reply channel a client names must
// also fit LCM's 63 characters (protocol/channels.h).
inline constexpr size_t kMaxNameLength = 63;
// The longest --control-token (the key of map edits' MAC; no longer on the wire).
inline constexpr size_t kMaxTokenLength = 256;
// Points, rays and boxes in one query message (60 KB of floats or doubles at most); clients
// split larger requests.
inline constexpr int64_t kMaxQueryPoints = 5000;
inline constexpr int64_t kMaxQueryRays = 2000;
inline constexpr int64_t kMaxQueryBoxes = 1000;
// Replies: voxels per region_chunk_t (16 bytes each), cells per grid_t message (rows are
// whole: a row wider than this goes alone).
inline constexpr int kRegionChunkVoxels = 4000;
inline constexpr int kGridChunkCells = 60000;

// --- Shards (docs/PROTOCOL.md, "Shards") -------------------------------------------------
// Most daemons in one shard set (map_info_t/server_status_t.shard_count; 6 box values each).
inline constexpr uint32_t kMaxShards = 64;

}  // namespace ort::protocol
