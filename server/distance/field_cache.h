// The last distance field computed, kept for the next query over the same cells: a box asked
// again (a planner asks for the area around its robot at a rate) re-reads its grid from the
// map, and only the part of the field that the changed cells can reach is transformed again.
//
// Why it is exact: a field is only ever read through its clamp (distance_field.h: a squared
// distance of pad^2 or more, pad = padding_cells(), reads as max_distance). A cell whose
// obstacle changed moves the clamped distance only of cells less than pad cells from it; those
// cells' clamped distances depend only on obstacles less than pad cells from them. So with C
// the bounding box of the changed cells, the EDT of the new grid restricted to C grown by
// 2 * pad gives every cell of C grown by pad its distance (exact below pad^2, at least pad^2
// above), and every other cell keeps its own. An empty C keeps the whole field.
//
// One entry (the grid and its field: 5 bytes a cell; the daemon caches boxes of at most
// DistanceLimits::single_grid_cells padded cells, 40 MB at its default); not thread-safe: the
// query worker is its only user.
#pragma once

#include <cstdint>
#include <optional>

#include "distance/distance_field.h"
#include "distance/occupancy_grid.h"

namespace ort::distance {

// What an update cost: counted by the server (status) and printed by the distance bench.
struct FieldCacheStats {
  int64_t full = 0;       // transformed whole: no entry, another box, or most of it changed
  int64_t unchanged = 0;  // the grid read equal to the cached one: no EDT
  int64_t partial = 0;    // only the changed part's reach transformed
  int64_t partial_cells = 0;
};

class FieldCache {
 public:
  // The cached grid's box when it can answer cells `want` under `opt` (same cell size, unknown
  // space and padding, `want` inside it and at least a quarter of its cells: reading the box
  // costs its cells), so the caller reads that box from the map.
  std::optional<CellBox> covering(const CellBox& want, const DistanceOptions& opt) const;
  // Whether the entry is for exactly this box under `opt` (update would reuse it).
  bool holds(const CellBox& box, const DistanceOptions& opt) const;

  // The field of `grid` (read from the map now): from the cached one where the entry is for
  // the same box and options, else computed whole; the entry becomes this grid's.
  const DistanceField& update(OccupancyGrid grid, const SquaredEdt& edt, double resolution, const DistanceOptions& opt);

  const FieldCacheStats& stats() const { return stats_; }

 private:
  bool same_key(const CellBox& box, const DistanceOptions& opt, double resolution) const;

  bool valid_ = false;
  OccupancyGrid grid_;
  DistanceField field_;
  int pad_ = 0;
  UnknownAs unknown_ = UnknownAs::kFree;
  double resolution_ = 0;
  FieldCacheStats stats_;
};

}  // namespace ort::distance
