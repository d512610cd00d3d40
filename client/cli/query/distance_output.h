// The distance queries' answers for people and scripts: one JSON document each, and a PNG
// of a box's horizontal slice (client/render/distance_slice.h).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "query_client/query_client.h"

namespace ort::client {

void write_distance_points_json(std::ostream& out, const std::vector<float>& xyz,
                                const octomap_rt::distance_points_reply_t& r);
void write_distance_path_json(std::ostream& out, const octomap_rt::distance_path_reply_t& r);
// A box's size, cell, origin and distance statistics (not every cell); `png` if one was written.
void write_distance_box_json(std::ostream& out, const DistanceBox& b, const std::string& png);
// The layer of cells holding height z (clamped to the box) as a picture.
void write_distance_slice(const DistanceBox& b, double z, const std::string& path);

}  // namespace ort::client
