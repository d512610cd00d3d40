// One JSON document per reply on stdout (`--json`), for scripts.
#pragma once

#include <ostream>
#include <vector>

#include "query_client/query_client.h"

namespace ort::client {

// points: {"snapshot_id", "map_utime", "status", "error", "results": [{"x","y","z","state","probability"}]}
void write_points_json(std::ostream& out, const std::vector<float>& xyz, const octomap_rt::occupancy_reply_t& r);
void write_rays_json(std::ostream& out, const octomap_rt::ray_reply_t& r);
void write_boxes_json(std::ostream& out, const octomap_rt::box_reply_t& r);
void write_region_json(std::ostream& out, const std::vector<octomap_rt::region_chunk_t>& chunks);
void write_grid_json(std::ostream& out, const Grid& g, const std::string& png_path);
void write_edit_json(std::ostream& out, const octomap_rt::map_edit_ack_t& a);
const char* state_name(int8_t occ);             // "unknown", "free", "occupied"
const char* status_name(int8_t status);         // "ok", "bad request", "not ready", "busy", "refused"
std::string json_quoted(const std::string& s);  // a JSON string literal

}  // namespace ort::client
