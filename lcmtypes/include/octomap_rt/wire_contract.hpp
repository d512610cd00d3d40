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
// occupancy_query_t, client -> server; the reply goes to the query's reply_channel.
inline constexpr const char* kQueryChannel = "OCTOMAP_RT_QUERY";

// --- Transport ----------------------------------------------------------------------------
// Host-local multicast (ttl=0: packets never leave the host). $LCM_DEFAULT_URL wins over it,
// as in every LCM program; the server adds a receive buffer size to udpm URLs.
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// --- Size limits --------------------------------------------------------------------------
// Points in one scan_t the server accepts by default (--max-points); 12 bytes each.
inline constexpr uint64_t kDefaultMaxScanPoints = 4'000'000;
// scan_t.robot_id: 1-32 of [A-Za-z0-9_-].
inline constexpr size_t kMaxRobotIdLength = 32;
// scan_t.map_frame.
inline constexpr size_t kMaxMapFrameLength = 256;
// occupancy_query_t: at most this many points (60 KB of xyz) in one query.
inline constexpr size_t kMaxQueryPoints = 5000;

}  // namespace octomap_rt::wire
