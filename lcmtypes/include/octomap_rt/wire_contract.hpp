// The wire contract of octomap-rt beside the message types it names: channel names, the
// default LCM URL and the size limits. The server, the client and the tests take them from
// here, so a channel is spelled once. (Hand-written; the *_t.hpp next to it come from lcm-gen.)
#pragma once

#include <cstddef>
#include <cstdint>

namespace octomap_rt::wire {

// --- Channels -----------------------------------------------------------------------------
// scan_t, robot -> server: the prefix followed by the robot id in upper case
// (OCTOMAP_RT_SCAN_HUSKY3); the server checks the message's robot_id against that suffix.
inline constexpr const char* kScanChannelPrefix = "OCTOMAP_RT_SCAN_";
// The server's default subscription: every scan channel.
inline constexpr const char* kScanChannelRegex = "OCTOMAP_RT_SCAN_.*";
// server_status_t, server -> all: 1 Hz and on every state change.
inline constexpr const char* kStatusChannel = "OCTOMAP_RT_STATUS";
// map_request_t, client -> server: send me a snapshot (or some of its chunks).
inline constexpr const char* kMapRequestChannel = "OCTOMAP_RT_MAP_REQUEST";
// map_info_t, server -> all: a snapshot is available.
inline constexpr const char* kMapInfoChannel = "OCTOMAP_RT_MAP_INFO";
// map_delta_t, server -> all: the changes of each applied scan (coalesced).
inline constexpr const char* kMapDeltaChannel = "OCTOMAP_RT_MAP_DELTA";
// map_chunk_t to one client: the prefix a client's reply_channel starts with by convention.
inline constexpr const char* kMapReplyPrefix = "OCTOMAP_RT_MAP_REPLY_";
// map_chunk_t broadcast (a request's reply_channel otherwise).
inline constexpr const char* kMapChunkChannel = "OCTOMAP_RT_MAP_CHUNK";
// Queries, client -> server; each reply goes to the query's reply_channel (the C++ client
// uses kQueryReplyPrefix + its id in upper case).
// occupancy_query_t -> occupancy_reply_t.
inline constexpr const char* kQueryChannel = "OCTOMAP_RT_QUERY";
// ray_query_t -> ray_reply_t.
inline constexpr const char* kQueryRaysChannel = "OCTOMAP_RT_QUERY_RAYS";
// box_query_t -> box_reply_t (counts, any occupied) or region_chunk_t (a region's voxels).
inline constexpr const char* kQueryBoxesChannel = "OCTOMAP_RT_QUERY_BOXES";
// grid_query_t -> grid_t rows.
inline constexpr const char* kQueryGridChannel = "OCTOMAP_RT_QUERY_GRID";
// map_edit_t -> map_edit_ack_t: clear a box, reset (refused without the control token).
inline constexpr const char* kMapEditChannel = "OCTOMAP_RT_MAP_EDIT";
inline constexpr const char* kQueryReplyPrefix = "OCTOMAP_RT_REPLY_";
// grid_t rows, server -> all: the 2D grid published at --grid-rate (request_id -1).
inline constexpr const char* kGridChannel = "OCTOMAP_RT_GRID";

// --- Transport ----------------------------------------------------------------------------
// Host-local multicast (ttl=0: packets never leave the host). $LCM_DEFAULT_URL wins over it,
// as in every LCM program; the server adds a receive buffer size to udpm URLs.
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// --- Size limits --------------------------------------------------------------------------
// Points in one scan_t the server accepts by default (--max-points); 12 bytes each.
inline constexpr uint64_t kDefaultMaxScanPoints = 4'000'000;
// scan_t.robot_id: 1-32 of [A-Za-z0-9_-].
inline constexpr size_t kMaxRobotIdLength = 32;
// Smallest positive scan_t.max_range [m] (<= 0 means "no limit of its own"): below it every
// ray ends in the sensor's voxel; the server refuses such a scan ("max range too small").
inline constexpr double kMinScanMaxRange = 1e-3;
// scan_t.map_frame.
inline constexpr size_t kMaxMapFrameLength = 256;
// occupancy_query_t: at most this many points (60 KB of xyz) in one query.
inline constexpr size_t kMaxQueryPoints = 5000;

}  // namespace octomap_rt::wire
