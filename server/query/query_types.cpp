#include "query/query_types.h"

namespace ort::query {

const char* to_string(VoxelState s) {
  switch (s) {
    case VoxelState::kUnknown: return "unknown";
    case VoxelState::kFree: return "free";
    case VoxelState::kOccupied: return "occupied";
  }
  return "?";
}

}  // namespace ort::query
