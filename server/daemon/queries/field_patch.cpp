#include "daemon/queries/field_patch.h"

#include <algorithm>
#include <vector>

#include "octree/batched/morton_order.h"

namespace ort::daemon {

std::optional<distance::GridPatch> patch_from_journal(ChangeJournal& journal, const octomap::OcTree& tree,
                                                      const distance::CellBox& box,
                                                      const distance::DistanceOptions& opt, uint64_t from,
                                                      uint64_t to) {
  if (opt.ownership.owns) return std::nullopt;
  const int64_t cells = box.dims.cells();
  std::vector<ClassChange> changes;
  // Past this many changes (map-wide) reading the box is about as cheap as going through them.
  const size_t most = size_t(std::max<int64_t>(cells, int64_t(1) << 18));
  if (!journal.changes_between(from, to, most, changes)) return std::nullopt;
  distance::GridPatch p;
  p.box = box, p.from = from, p.to = to;
  const int m = box.cell_voxels;
  const int64_t n[3] = {box.dims.nx, box.dims.ny, box.dims.nz};
  for (const ClassChange& c : changes) {
    uint16_t k[3];
    morton_decode(c.morton(), k[0], k[1], k[2]);
    int64_t idx[3];
    bool in = true;
    for (int a = 0; a < 3 && in; ++a) {
      const int64_t off = int64_t(k[a]) - box.key_lo[a];
      idx[a] = off / m;
      in = off >= 0 && idx[a] < n[a];
    }
    if (!in) continue;
    const auto index = static_cast<uint32_t>(idx[0] + n[0] * (idx[1] + n[1] * idx[2]));
    p.cells.push_back(distance::CellChange{index, uint8_t(c.occupied() ? 1 : 0)});
  }
  if (m == 1) return p;
  // A coarse cell is an obstacle if any of its voxels is (or is unknown, with kOccupied): its
  // changed voxels alone do not say, so each changed cell is read again, once.
  std::vector<uint32_t> touched;
  touched.reserve(p.cells.size());
  for (const distance::CellChange& c : p.cells) touched.push_back(c.index);
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  p.cells.clear();
  for (uint32_t index : touched) {
    distance::CellBox one;
    one.cell_voxels = m;
    one.dims = distance::GridDims{1, 1, 1};
    const int64_t i = index % n[0], j = (index / n[0]) % n[1], kk = index / (n[0] * n[1]);
    one.key_lo = {box.key_lo[0] + i * m, box.key_lo[1] + j * m, box.key_lo[2] + kk * m};
    const distance::OccupancyGrid g = distance::read_occupancy(tree, one, opt.unknown);
    p.cells.push_back(distance::CellChange{index, g.occupied[0]});
  }
  return p;
}

}  // namespace ort::daemon
