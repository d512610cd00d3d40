// Distance queries across a shard set (docs/PROTOCOL.md, "Shards" and "Distance queries"):
// each shard answers for the obstacles of its own regions (its occupied voxels and, with
// unknown as occupied, its own unknown space), so the set's obstacles are the union of the
// shards' and the distance of a cell is the smallest of the shards' distances for it, exactly
// (the nearest of a union is the nearest of the parts' nearest; the clamp commutes with the
// minimum). Gradients are central differences of that merged field, so the client asks for the
// neighbours too and computes them as a server does. A shard that did not answer leaves its
// obstacles out: the merged distances are then upper bounds, and the answer says so.
//
// What is asked of the shards and how their answers merge, as plain functions (ShardQueries
// sends and gathers; tests merge answers read straight from shard maps).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "octomap_rt/distance_path_reply_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "protocol/shards/shard_set.h"
#include "query_client/distance_box.h"
#include "query_client/query_client.h"

namespace ort::client {

// Cells of padding a server reads around what a query asks (PROTOCOL.md: ceil(max_distance /
// cell) + 1): obstacles farther than that from every asked cell do not count.
int distance_padding_cells(double max_distance, double resolution, int cell_voxels);

// The finest voxel key of a coordinate (OctoMap's coordToKeyChecked); false outside the range.
bool voxel_key(double coordinate, double resolution, int64_t& key);

// The shards owning a region that meets the key box [lo, hi] (inclusive, clamped to the key
// range), in index order: the only ones whose obstacles can count for cells within it.
std::vector<uint32_t> shards_meeting(const protocol::ShardSet& set, std::array<int64_t, 3> lo,
                                     std::array<int64_t, 3> hi);

// --- points ---------------------------------------------------------------------------
// Each point, then the centres of its voxel's six neighbours (-x, +x, -y, +y, -z, +z): 7 points
// a point, what the shards are asked when the gradient is wanted. Throws std::invalid_argument
// for a point outside the key range.
std::vector<float> with_neighbours(std::span<const float> xyz, double resolution);
// The shards' replies to the same points (nullptr: no answer) merged: per point the smallest
// distance. With `gradient` the replies are for with_neighbours(xyz) and the result holds the
// `points` points with the gradient of the merged field (distance_field.h's definition).
octomap_rt::distance_points_reply_t merge_distance_points(
    const std::vector<const octomap_rt::distance_points_reply_t*>& got, size_t points, bool gradient);

// --- a box ------------------------------------------------------------------------------
// The box one cell larger on every side, its corners at voxel centres of the outer cells (so
// no rounding moves a corner into another cell): what the shards are asked with the gradient.
// Throws std::invalid_argument for a corner outside the key range.
Box grown_distance_box(const Box& b, double resolution, int cell_voxels);
// The shards' boxes (the same cells on each; nullptr: no answer) merged cell by cell. With
// `gradient` they are grown_distance_box's and the result is the box asked for, with the
// gradient of the merged field. Throws DistanceBoxError when the shards' boxes differ.
DistanceBox merge_distance_boxes(const std::vector<const DistanceBox*>& got, bool gradient, double resolution);

// --- a path -----------------------------------------------------------------------------
// The smallest of the shards' clearances; where it is: the first sample with that distance.
octomap_rt::distance_path_reply_t merge_distance_paths(
    const std::vector<const octomap_rt::distance_path_reply_t*>& got);

}  // namespace ort::client
