// Everything a program needs to ask octomap-rt-server about its map, in one namespace:
// ort::client. The query client (query_client.h), the reply and request types it uses (the
// generated LCM types of package octomap_rt, by the names below) and the two protocol helpers
// a program starts with: the LCM URL and the server's namespace. Installed with the package
// (find_package(octomap_rt), target octomap_rt::query_client); client/examples/query_point
// is a program built on it alone.
#pragma once

#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "query_client/query_client.h"

namespace ort::client {

// Replies (their status constants too: OccupancyReply::REPLY_OK, OccupancyReply::OCC_OCCUPIED).
using OccupancyReply = octomap_rt::occupancy_reply_t;
using RayReply = octomap_rt::ray_reply_t;
using BoxReply = octomap_rt::box_reply_t;
using RegionChunk = octomap_rt::region_chunk_t;
using GridChunk = octomap_rt::grid_t;
using DistancePointsReply = octomap_rt::distance_points_reply_t;
using DistancePathReply = octomap_rt::distance_path_reply_t;
using EditAck = octomap_rt::map_edit_ack_t;
// Requests' constants: BoxQuery::MODE_COUNTS, MapEdit::OP_CLEAR_TO_FREE, MapEdit::FLAG_INCLUDE_UNKNOWN.
using BoxQuery = octomap_rt::box_query_t;
using MapEdit = octomap_rt::map_edit_t;

// The LCM URL to use: `requested`, else $LCM_DEFAULT_URL, else the host-local udpm URL.
using protocol::lcm_url_or_default;
// The server's namespace: `requested`, else $OCTOMAP_RT_NAMESPACE, else none.
using protocol::namespace_from;

}  // namespace ort::client
