#include "engine/ray_space.h"

#include <algorithm>
#include <stdexcept>

namespace ort {

std::vector<KeyBox> plan_windows(const KeyBox& space, uint64_t capacity_voxels, int margin) {
  std::vector<KeyBox> out;
  if (space.empty()) return out;
  if (capacity_voxels == 0) throw std::invalid_argument("plan_windows: grid holds no voxels");
  KeyBox wide = space;
  for (int i = 0; i < 3; ++i) {
    wide.lo[i] = std::max(0, space.lo[i] - margin);
    wide.hi[i] = std::min(65535, space.hi[i] + margin);
  }
  std::vector<KeyBox> todo{wide};
  while (!todo.empty()) {
    KeyBox b = todo.back();
    todo.pop_back();
    if (b.voxel_count() <= capacity_voxels) {
      out.push_back(b);
      continue;
    }
    int axis = 0;
    for (int i = 1; i < 3; ++i)
      if (b.hi[i] - b.lo[i] > b.hi[axis] - b.lo[axis]) axis = i;
    if (b.hi[axis] == b.lo[axis]) throw std::invalid_argument("plan_windows: grid smaller than one voxel row");
    const int mid = b.lo[axis] + (b.hi[axis] - b.lo[axis]) / 2;
    KeyBox a = b, c = b;
    a.hi[axis] = mid;
    c.lo[axis] = mid + 1;
    todo.push_back(c);
    todo.push_back(a);
  }
  return out;
}

}  // namespace ort
