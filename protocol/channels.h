// Every channel of the protocol, spelled once (docs/PROTOCOL.md), and the namespace rule that
// renames them all: with namespace NS each name becomes NS_ + the name below, reply channels
// included; without one the names are these. The server, the clients and the tests take their
// names from here (the Python and Java clients from a table that tests/protocol checks
// against this file).
#pragma once

#include <string>
#include <string_view>

namespace ort::protocol {

// --- Today's names (no namespace) ---------------------------------------------------------
// scan_t, robot -> server: the prefix followed by the robot id in upper case
// (OCTOMAP_RT_SCAN_HUSKY3); the server checks the message's robot_id against that suffix.
inline constexpr const char* kScanChannelPrefix = "OCTOMAP_RT_SCAN_";
// server_status_t, server -> all: 1 Hz and on every state change.
inline constexpr const char* kStatusChannel = "OCTOMAP_RT_STATUS";
// map_request_t, client -> server: send me a snapshot (or some of its chunks).
inline constexpr const char* kMapRequestChannel = "OCTOMAP_RT_MAP_REQUEST";
// map_info_t, server -> all: a snapshot is available.
inline constexpr const char* kMapInfoChannel = "OCTOMAP_RT_MAP_INFO";
// map_delta_t, server -> all: the changes of each applied scan (coalesced).
inline constexpr const char* kMapDeltaChannel = "OCTOMAP_RT_MAP_DELTA";
// map_chunk_t to one client: a map request's reply_channel is this prefix + the client id
// (reply_channel_for).
inline constexpr const char* kMapReplyPrefix = "OCTOMAP_RT_MAP_REPLY_";
// Queries, client -> server; each reply goes to the query's reply_channel (the C++ and
// Python clients use kQueryReplyPrefix + their id in upper case).
// occupancy_query_t -> occupancy_reply_t.
inline constexpr const char* kQueryChannel = "OCTOMAP_RT_QUERY";
// ray_query_t -> ray_reply_t.
inline constexpr const char* kQueryRaysChannel = "OCTOMAP_RT_QUERY_RAYS";
// box_query_t -> box_reply_t (counts, any occupied) or region_chunk_t (a region's voxels).
inline constexpr const char* kQueryBoxesChannel = "OCTOMAP_RT_QUERY_BOXES";
// grid_query_t -> grid_t rows.
inline constexpr const char* kQueryGridChannel = "OCTOMAP_RT_QUERY_GRID";
// distance_query_t -> distance_points_reply_t, distance_box_chunk_t (a box's field, zstd, in
// chunks) or distance_path_reply_t: distance to the nearest obstacle. Short, so that no name
// is longer than OCTOMAP_RT_MAP_REQUEST and a 40-character namespace still fits every one.
inline constexpr const char* kQueryDistanceChannel = "OCTOMAP_RT_QUERY_DIST";
// map_edit_t -> map_edit_ack_t: clear a box, reset (refused without the control token).
inline constexpr const char* kMapEditChannel = "OCTOMAP_RT_MAP_EDIT";
inline constexpr const char* kQueryReplyPrefix = "OCTOMAP_RT_REPLY_";
// grid_t rows, server -> all: the 2D grid published at --grid-rate (request_id -1).
inline constexpr const char* kGridChannel = "OCTOMAP_RT_GRID";
// octomap.raw_t, server -> LCM's OctoMap viewers (--octomap-raw-rate): their channel name.
inline constexpr const char* kOctomapRawChannel = "OCTOMAP";

// A shard's own channels are in namespace NS_ + this + its index (SHARD2, lab2_SHARD2;
// protocol/shards/shard_set.h's shard_namespace).
inline constexpr const char* kShardNamespacePrefix = "SHARD";

// --- Namespaces ---------------------------------------------------------------------------
// Where the namespace comes from when no --namespace is given.
inline constexpr const char* kNamespaceEnv = "OCTOMAP_RT_NAMESPACE";
// LCM refuses channel names longer than this (lcm-1.3.1's LCM_MAX_CHANNEL_NAME_LENGTH).
inline constexpr size_t kMaxChannelLength = 63;

// Every channel in one namespace. Prefixes end in '_' (a robot id or client id follows).
struct Channels {
  std::string ns;  // "" = today's names
  std::string scan_prefix, status, map_request, map_info, map_delta, map_reply_prefix, query_points, query_rays,
      query_boxes, query_grid, query_distance, map_edit, query_reply_prefix, grid, octomap_raw;

  // The server's default scan subscription: every scan channel of the namespace.
  std::string scan_regex() const { return scan_prefix + ".*"; }
};

// "" when `ns` may name a namespace ("", or 1.. of [A-Za-z0-9_]), else why not.
std::string check_namespace(std::string_view ns);
// `requested` when not empty, else $OCTOMAP_RT_NAMESPACE, else "" (today's names).
std::string namespace_from(const std::string& requested);
// `name` in namespace `ns`: NS_ + name, or name itself when `ns` is "".
std::string in_namespace(std::string_view ns, std::string_view name);
// The channels of namespace `ns`. Throws std::invalid_argument (saying why) when `ns` breaks
// check_namespace or makes a name longer than LCM takes (a prefix with one character after it);
// a client checks its own reply channel with check_channel_length.
Channels channels_in(std::string_view ns);
// "" when LCM takes `channel` (1..kMaxChannelLength characters), else why not.
std::string check_channel_length(std::string_view channel);

}  // namespace ort::protocol
