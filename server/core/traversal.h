// Which voxels a ray updates: the one choice every back end implements.
#pragma once

#include <string>

namespace ort {

enum class Traversal {
  kOctomap,  // OctoMap 1.9.7's computeRayKeys walk, bit for bit (the default)
  kExact,    // every voxel whose closed box the segment touches (the paper's geometry)
};

const char* to_string(Traversal t);
bool parse_traversal(const std::string& s, Traversal& out);

}  // namespace ort
