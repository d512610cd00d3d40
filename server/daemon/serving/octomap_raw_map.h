// The map as an `octomap.raw_t` message for LCM's OctoMap viewers: the .bt OctoMap's
// OcTree::writeBinary writes (max likelihood, pruned; core/file_checks/octree_binary.h), at
// full depth when it fits the size cap, else depth-limited (the tree cut at a depth: each node
// there becomes a voxel of a coarser map with the node's value, which is its most occupied
// child's, as OctoMap keeps inner nodes), else not at all, with a note that says why.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <octomap/OcTree.h>

#include "octomap/raw_t.hpp"

namespace ort::daemon {

struct RawMapOptions {
  size_t max_bytes = 200 * 1024;  // whole encoded message
  unsigned min_depth = 10;        // coarsest level tried (16 = full; 10: 64 voxels a side)
};

struct RawMap {
  std::optional<octomap::raw_t> message;  // empty: too large even at min_depth
  unsigned depth = 16;                    // tree depth it was cut at (16: the whole tree)
  size_t full_bytes = 0;                  // encoded size at full depth
  std::string note;                       // "" at full depth; else what was cut, or why nothing was sent
};

RawMap make_raw_map(const octomap::OcTree& tree, int64_t utime, const RawMapOptions& options);

// octomap_server's occupancy_min_z/max_z for the map a viewer shows: deletes from `tree` (a
// copy: the map of record is never filtered) every occupied leaf whose centre z is not
// strictly inside (min_z, max_z), as octomap_server leaves such cells out of its occupied
// cells and its 2D map; free leaves stay. Returns how many leaves went.
size_t drop_occupied_outside_band(octomap::OcTree& tree, double min_z, double max_z);

// Encoded size of a raw_t carrying `data_bytes` of map.
size_t raw_message_bytes(size_t data_bytes);

// The tree cut at `depth` (< its depth) as a map of 2^(16 - depth) times coarser voxels:
// every node at `depth`, and every larger leaf above it, keeps its value.
octomap::OcTree cut_at_depth(const octomap::OcTree& tree, unsigned depth);

}  // namespace ort::daemon
