#include "gpu/ray_space_windows.h"

#include <algorithm>
#include <stdexcept>

namespace ort::gpu {
namespace {

void cut(const KeyBox& b, uint64_t capacity, std::vector<KeyBox>& out) {
  const uint64_t count = b.voxel_count();
  if (count <= capacity) {
    out.push_back(b);
    return;
  }
  int axis = 0;
  for (int i = 1; i < 3; ++i) {
    if (b.hi[i] - b.lo[i] > b.hi[axis] - b.lo[axis]) axis = i;
  }
  const uint64_t length = uint64_t(b.hi[axis] - b.lo[axis] + 1);
  const uint64_t slab = count / length;  // voxels in a slab one voxel thick
  const int thickness = int(std::max<uint64_t>(1, capacity / slab));
  for (int lo = b.lo[axis]; lo <= b.hi[axis]; lo += thickness) {
    KeyBox piece = b;
    piece.lo[axis] = lo;
    piece.hi[axis] = std::min(b.hi[axis], lo + thickness - 1);
    cut(piece, capacity, out);  // only recurses when one slab alone exceeds the capacity
  }
}

}  // namespace

std::vector<KeyBox> plan_ray_space_windows(const KeyBox& keys, uint64_t capacity_voxels, int margin) {
  std::vector<KeyBox> out;
  if (keys.empty()) return out;
  if (capacity_voxels == 0) throw std::invalid_argument("plan_ray_space_windows: the grid holds no voxels");
  KeyBox wide;
  for (int i = 0; i < 3; ++i) {
    wide.lo[i] = std::max(0, keys.lo[i] - margin);
    wide.hi[i] = std::min(65535, keys.hi[i] + margin);
  }
  cut(wide, capacity_voxels, out);
  return out;
}

}  // namespace ort::gpu
