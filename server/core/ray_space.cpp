#include "core/ray_space.h"

#include <algorithm>
#include <stdexcept>

namespace ort {
namespace {

// Slabs across the longest axis, as thick as the capacity allows: each window means one more
// walk of every ray that meets it, so fewer windows is faster. Recurses only when a single
// slab alone exceeds the capacity.
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
    cut(piece, capacity, out);
  }
}

}  // namespace

std::vector<KeyBox> plan_windows(const KeyBox& space, uint64_t capacity_voxels, int margin) {
  std::vector<KeyBox> out;
  if (space.empty()) return out;
  if (capacity_voxels == 0) throw std::invalid_argument("plan_windows: the grid holds no voxels");
  KeyBox wide;
  for (int i = 0; i < 3; ++i) {
    wide.lo[i] = std::max(0, space.lo[i] - margin);
    wide.hi[i] = std::min(65535, space.hi[i] + margin);
  }
  cut(wide, capacity_voxels, out);
  return out;
}

}  // namespace ort
