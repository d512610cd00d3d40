#include "distance/field_cache.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <utility>

namespace ort::distance {
namespace {

// The cells [lo, hi] (inclusive, per axis) of a grid, in its own index space.
struct IndexBox {
  std::array<int64_t, 3> lo{}, hi{};
  int64_t cells() const { return (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1); }
};

// The bounding box of the cells where `a` and `b` differ; false where they are equal.
bool changed_box(const OccupancyGrid& a, const OccupancyGrid& b, IndexBox& out) {
  const GridDims d = a.box.dims;
  bool any = false;
  for (int64_t k = 0; k < d.nz; ++k)
    for (int64_t j = 0; j < d.ny; ++j) {
      const size_t row = size_t((k * d.ny + j) * d.nx);
      const uint8_t* x = a.occupied.data() + row;
      const uint8_t* y = b.occupied.data() + row;
      if (std::memcmp(x, y, size_t(d.nx)) == 0) continue;
      int64_t first = 0, last = d.nx - 1;
      while (x[first] == y[first]) ++first;
      while (x[last] == y[last]) --last;
      if (!any) {
        out.lo = {first, j, k}, out.hi = {last, j, k};
        any = true;
        continue;
      }
      out.lo[0] = std::min(out.lo[0], first), out.hi[0] = std::max(out.hi[0], last);
      out.lo[1] = std::min(out.lo[1], j), out.hi[1] = std::max(out.hi[1], j);
      out.hi[2] = k;
    }
  return any;
}

IndexBox grown(const IndexBox& b, int64_t by, const GridDims& d) {
  const int64_t n[3] = {d.nx, d.ny, d.nz};
  IndexBox g;
  for (int a = 0; a < 3; ++a) g.lo[a] = std::max<int64_t>(0, b.lo[a] - by), g.hi[a] = std::min(n[a] - 1, b.hi[a] + by);
  return g;
}

bool inside(const CellBox& want, const CellBox& have) {
  const int64_t want_n[3] = {want.dims.nx, want.dims.ny, want.dims.nz};
  const int64_t have_n[3] = {have.dims.nx, have.dims.ny, have.dims.nz};
  for (int a = 0; a < 3; ++a)
    if (want.key_lo[a] < have.key_lo[a] ||
        want.key_lo[a] + want_n[a] * want.cell_voxels > have.key_lo[a] + have_n[a] * have.cell_voxels)
      return false;
  return true;
}

bool same_box(const CellBox& a, const CellBox& b) {
  return a.key_lo == b.key_lo && a.cell_voxels == b.cell_voxels && a.dims.nx == b.dims.nx && a.dims.ny == b.dims.ny &&
         a.dims.nz == b.dims.nz;
}

}  // namespace

bool FieldCache::same_key(const CellBox& box, const DistanceOptions& opt, double resolution) const {
  return valid_ && box.cell_voxels == grid_.box.cell_voxels && opt.unknown == unknown_ && resolution == resolution_ &&
         padding_cells(opt, resolution) == pad_;
}

std::optional<CellBox> FieldCache::covering(const CellBox& want, const DistanceOptions& opt) const {
  if (!same_key(want, opt, resolution_) || !inside(want, grid_.box)) return std::nullopt;
  // Reading the cached box costs its cells: for far fewer, their own grid's EDT is the cheaper.
  if (want.dims.cells() * 4 < grid_.box.dims.cells()) return std::nullopt;
  return grid_.box;
}

bool FieldCache::holds(const CellBox& box, const DistanceOptions& opt) const {
  return same_key(box, opt, resolution_) && same_box(box, grid_.box);
}

const DistanceField& FieldCache::update(OccupancyGrid grid, const SquaredEdt& edt, double resolution,
                                        const DistanceOptions& opt) {
  const int pad = padding_cells(opt, resolution);
  IndexBox changed;
  const bool reuse = same_key(grid.box, opt, resolution) && same_box(grid.box, grid_.box);
  if (reuse && !changed_box(grid_, grid, changed)) {
    ++stats_.unchanged;
  } else if (reuse && grown(changed, 2 * int64_t(pad), grid.box.dims).cells() * 2 < grid.box.dims.cells()) {
    // The changed cells' reach (grown by pad) from the EDT of their reach's obstacles (by 2 pad).
    const IndexBox src = grown(changed, 2 * int64_t(pad), grid.box.dims);
    const IndexBox dst = grown(changed, pad, grid.box.dims);
    const GridDims sd{int(src.hi[0] - src.lo[0] + 1), int(src.hi[1] - src.lo[1] + 1), int(src.hi[2] - src.lo[2] + 1)};
    const GridDims d = grid.box.dims;
    std::vector<uint8_t> occ(size_t(sd.cells()));
    for (int64_t k = 0; k < sd.nz; ++k)
      for (int64_t j = 0; j < sd.ny; ++j)
        std::memcpy(occ.data() + size_t((k * sd.ny + j) * sd.nx),
                    grid.occupied.data() + size_t(((src.lo[2] + k) * d.ny + src.lo[1] + j) * d.nx + src.lo[0]),
                    size_t(sd.nx));
    std::vector<uint32_t> sq(occ.size());
    edt(occ, sd, sq);
    for (int64_t k = dst.lo[2]; k <= dst.hi[2]; ++k)
      for (int64_t j = dst.lo[1]; j <= dst.hi[1]; ++j)
        std::memcpy(field_.squared.data() + size_t((k * d.ny + j) * d.nx + dst.lo[0]),
                    sq.data() + size_t(((k - src.lo[2]) * sd.ny + j - src.lo[1]) * sd.nx + dst.lo[0] - src.lo[0]),
                    size_t(dst.hi[0] - dst.lo[0] + 1) * sizeof(uint32_t));
    ++stats_.partial;
    stats_.partial_cells += sd.cells();
  } else {
    field_ = compute_field(grid, edt, resolution, opt);
    ++stats_.full;
  }
  grid_ = std::move(grid);
  field_.box = grid_.box;
  field_.cell_size = resolution * grid_.box.cell_voxels;
  field_.max_distance = opt.max_distance;
  pad_ = pad, unknown_ = opt.unknown, resolution_ = resolution, valid_ = true;
  return field_;
}

}  // namespace ort::distance
