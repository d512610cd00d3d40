// A world made from a real OctoMap map: its occupied voxels become an occupancy grid that the
// simulated sensors ray cast against, and the longest walk through its known free space at
// sensor height becomes the path (in geb079.bt, OctoMap's FR-079 map, that is the corridor).
#pragma once

#include <string>

#include "scene/procedural_worlds.h"

namespace ort::scene {

// Reads a .bt or .ot OcTree. Throws std::runtime_error when the file cannot be read or has no
// free space to put a sensor in. `sensor_height` is above the lowest occupied layer (the floor).
World make_world_from_octomap(const std::string& map_path, double sensor_height);

}  // namespace ort::scene
