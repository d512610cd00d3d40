#include "distance/field_cache.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <utility>

namespace ort::distance {

void IndexBox::add(int64_t i, int64_t j, int64_t k, bool& any) {
  if (!any) {
    lo = {i, j, k}, hi = {i, j, k};
    any = true;
    return;
  }
  lo = {std::min(lo[0], i), std::min(lo[1], j), std::min(lo[2], k)};
  hi = {std::max(hi[0], i), std::max(hi[1], j), std::max(hi[2], k)};
}

namespace {

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
      out.add(first, j, k, any);
      out.add(last, j, k, any);
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

// The field of `grid` after its cells in `changed` changed (`field` was the field before):
// the changed cells' reach (grown by pad) from the EDT of their reach's obstacles (by 2 pad).
void transform_part(const OccupancyGrid& grid, const IndexBox& changed, int pad, const SquaredEdt& edt,
                    DistanceField& field, FieldCacheStats& stats) {
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
      std::memcpy(field.squared.data() + size_t((k * d.ny + j) * d.nx + dst.lo[0]),
                  sq.data() + size_t(((k - src.lo[2]) * sd.ny + j - src.lo[1]) * sd.nx + dst.lo[0] - src.lo[0]),
                  size_t(dst.hi[0] - dst.lo[0] + 1) * sizeof(uint32_t));
  ++stats.partial;
  stats.partial_cells += sd.cells();
}

// Whether the changed cells' reach is small enough for a partial transform to pay.
bool partial_pays(const IndexBox& changed, int pad, const GridDims& d) {
  return grown(changed, 2 * int64_t(pad), d).cells() * 2 < d.cells();
}

}  // namespace

FieldCache::Key FieldCache::key_of(const CellBox& box, const DistanceOptions& opt, double resolution) {
  return Key{box, padding_cells(opt, resolution), opt.unknown, resolution};
}

bool FieldCache::same_key(const Key& a, const Key& b, bool with_box) {
  return a.box.cell_voxels == b.box.cell_voxels && a.pad == b.pad && a.unknown == b.unknown &&
         a.resolution == b.resolution && (!with_box || same_cells(a.box, b.box));
}

std::optional<FieldCache::Pending> FieldCache::pending(const DistanceOptions& opt, double resolution) const {
  CellBox probe;
  probe.cell_voxels = opt.cell_voxels;
  if (!pending_valid_ || !same_key(pending_key_, key_of(probe, opt, resolution), false)) return std::nullopt;
  return Pending{pending_key_.box, pending_version_};
}

std::optional<CellBox> FieldCache::covering(const CellBox& want, const DistanceOptions& opt, double resolution,
                                            bool cheap) const {
  const auto p = pending(opt, resolution);
  if (!p || want.cell_voxels != p->box.cell_voxels || !inside(want, p->box)) return std::nullopt;
  // Reading the cached box from the map costs its cells: for far fewer, their own grid is cheaper.
  if (!cheap && want.dims.cells() * 4 < p->box.dims.cells()) return std::nullopt;
  return p->box;
}

void FieldCache::will_hold(const CellBox& box, const DistanceOptions& opt, double resolution, uint64_t version) {
  pending_key_ = key_of(box, opt, resolution);
  pending_version_ = version;
  pending_valid_ = true;
}

void FieldCache::will_advance(uint64_t version) { pending_version_ = version; }

template <class BringGrid>
const DistanceField& FieldCache::settle(const Key& key, uint64_t version, const SquaredEdt& edt,
                                        const DistanceOptions& opt, BringGrid&& bring_grid) {
  try {
    const bool was_valid = valid_;
    valid_ = false;  // until the field is grid_'s
    const Change c = bring_grid(was_valid);
    if (c.reuse && !c.any) {
      ++stats_.unchanged;
    } else {
      memo_.reset();
      if (c.reuse && partial_pays(c.box, key.pad, grid_.box.dims)) {
        transform_part(grid_, c.box, key.pad, edt, field_, stats_);
      } else {
        field_ = compute_field(grid_, edt, key.resolution, opt);
        ++stats_.full;
      }
    }
  } catch (...) {
    pending_valid_ = false;
    memo_.reset();
    throw;
  }
  field_.box = grid_.box;
  field_.cell_size = key.resolution * grid_.box.cell_voxels;
  field_.max_distance = opt.max_distance;
  key_ = key, version_ = version, valid_ = true;
  return field_;
}

const DistanceField& FieldCache::update(OccupancyGrid grid, const SquaredEdt& edt, double resolution,
                                        const DistanceOptions& opt, uint64_t version) {
  const Key key = key_of(grid.box, opt, resolution);
  return settle(key, version, edt, opt, [&](bool was_valid) {
    Change c;
    c.reuse = was_valid && same_key(key, key_, true);
    ++stats_.reread;
    c.any = !c.reuse || changed_box(grid_, grid, c.box);
    grid_ = std::move(grid);
    return c;
  });
}

const DistanceField& FieldCache::update(const GridPatch& patch, const SquaredEdt& edt, const DistanceOptions& opt) {
  if (!valid_ || !same_cells(patch.box, key_.box) || version_ != patch.from ||
      !same_key(key_of(patch.box, opt, key_.resolution), key_, true)) {
    pending_valid_ = false;
    throw DistanceError("the distance field cache lost its entry (an update before this one failed): ask again");
  }
  return settle(key_, patch.to, edt, opt, [&](bool) {
    Change c;
    c.reuse = true;
    const GridDims d = grid_.box.dims;
    for (const CellChange& ch : patch.cells) {
      uint8_t& cell = grid_.occupied.at(ch.index);
      if (cell == ch.occupied) continue;
      cell = ch.occupied;
      const int64_t i = ch.index % d.nx, j = (ch.index / d.nx) % d.ny, k = ch.index / (int64_t(d.nx) * d.ny);
      c.box.add(i, j, k, c.any);
    }
    ++stats_.patched;
    stats_.patch_changes += int64_t(patch.cells.size());
    return c;
  });
}

}  // namespace ort::distance
