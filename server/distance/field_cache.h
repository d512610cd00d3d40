// The last distance field computed, kept for the next query over the same cells: a box asked
// again (a planner asks for the area around its robot at a rate) gets its grid brought up to
// date, and only the part of the field that the changed cells can reach is transformed again.
//
// Why it is exact: a field is only ever read through its clamp (distance_field.h: a squared
// distance of pad^2 or more, pad = padding_cells(), reads as max_distance). A cell whose
// obstacle changed moves the clamped distance only of cells less than pad cells from it; those
// cells' clamped distances depend only on obstacles less than pad cells from them. So with C
// the bounding box of the changed cells, the EDT of the new grid restricted to C grown by
// 2 * pad gives every cell of C grown by pad its distance (exact below pad^2, at least pad^2
// above), and every other cell keeps its own. An empty C keeps the whole field.
//
// Two ways to bring the grid up to date: a grid read from the map again (compared with the
// cached one), or a patch: the cells that changed since the entry's map state, which the
// caller knows from the map's change lists (daemon/map/change_journal.h), so the read under
// the map lock costs the changes, not the box. Reads are decided under the map lock and their
// updates run later, in the same order, on one thread; the read side asks the state the entry
// will have once the updates of the reads so far ran (pending()).
//
// One entry (the grid and its field: 5 bytes a cell; the daemon caches boxes of at most
// DistanceLimits::single_grid_cells padded cells, 40 MB at its default) and the last box
// reply's frames (KeptFrames: 4 bytes a box cell, 16 with the gradient, and their compressed
// bytes); not thread-safe: the query worker is its only user.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "distance/distance_field.h"
#include "distance/occupancy_grid.h"

namespace ort::distance {

// What the updates cost: counted by the server (status) and printed by the distance bench.
struct FieldCacheStats {
  int64_t full = 0;       // transformed whole: no entry, another box, or most of it changed
  int64_t unchanged = 0;  // the grid equal to the cached one: no EDT
  int64_t partial = 0;    // only the changed part's reach transformed
  int64_t partial_cells = 0;
  int64_t patched = 0;        // updates from a patch (no grid read from the map)
  int64_t patch_changes = 0;  // the cell changes those patches carried
  int64_t reread = 0;         // updates from a grid read from the map again
  int64_t replies_kept = 0;   // box replies sent the bytes kept from the last one (field unchanged)
  int64_t frames = 0;         // zstd frames (z-slabs) of the box replies made again
  int64_t frames_kept = 0;    // of those, kept from the last reply (the slab's bytes unchanged)
};

// A box reply's frames as last made (daemon/queries/box_frames.h): per frame its bytes before
// and after compression, under the key of the box and options they were made for. Correct
// whatever the field did since: a frame is reused only where its bytes are equal.
struct KeptFrames {
  std::string key;
  std::vector<std::string> raw, packed;
};

// The cells [lo, hi] (inclusive, per axis) of a grid, in its own index space: where a grid
// changed.
struct IndexBox {
  std::array<int64_t, 3> lo{}, hi{};
  int64_t cells() const { return (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1); }
  // Grows the box to hold (i, j, k); the first cell (`any` false) makes it that cell alone.
  void add(int64_t i, int64_t j, int64_t k, bool& any);
};

// A cell of the cached grid and whether it is an obstacle now.
struct CellChange {
  uint32_t index = 0;  // x + nx * (y + ny * z) in the grid
  uint8_t occupied = 0;
};
// The changes that take the entry from map state `from` to `to`, in the order they happened.
struct GridPatch {
  CellBox box;
  uint64_t from = 0, to = 0;
  std::vector<CellChange> cells;
};

class FieldCache {
 public:
  // --- read side (under the map lock) ---
  // The entry's box and map state once the updates of the reads so far ran, when it is for
  // `opt` (same cell size, unknown space and padding).
  struct Pending {
    CellBox box;
    uint64_t version = 0;
  };
  std::optional<Pending> pending(const DistanceOptions& opt, double resolution) const;
  // The pending entry's box when it can answer cells `want` (inside it; unless the caller
  // can bring it up to date cheaply, `cheap`, at least a quarter of its cells: reading the box
  // from the map costs its cells).
  std::optional<CellBox> covering(const CellBox& want, const DistanceOptions& opt, double resolution, bool cheap) const;
  // A read of grid `box` at map state `version` whose update will take the entry whole.
  void will_hold(const CellBox& box, const DistanceOptions& opt, double resolution, uint64_t version);
  // A read whose patch takes the pending entry to `version`.
  void will_advance(uint64_t version);

  // --- update side (after the lock, in the order of the reads) ---
  // The field of `grid` (read from the map at `version`): from the cached one where the entry
  // is for the same box and options, else computed whole; the entry becomes this grid's.
  const DistanceField& update(OccupancyGrid grid, const SquaredEdt& edt, double resolution, const DistanceOptions& opt,
                              uint64_t version = 0);
  // The field after `patch`; DistanceError when the entry is not at patch.from for its box
  // (an update before it failed): the query is refused, the next read reads the map again.
  const DistanceField& update(const GridPatch& patch, const SquaredEdt& edt, const DistanceOptions& opt);

  // Bytes made from the field as it is now (a box reply's compressed blob) under `key`: a box
  // asked again over a field that did not change is sent the same bytes, so they are kept, not
  // made again. Forgotten whenever the field changes.
  struct Memo {
    std::string key;
    std::string bytes;
    int64_t raw_size = 0;
  };
  const Memo* memo(const std::string& key) {
    if (!memo_ || memo_->key != key) return nullptr;
    ++stats_.replies_kept;
    return &*memo_;
  }
  const Memo& keep_memo(Memo m) { return memo_.emplace(std::move(m)); }

  // The frames of the last box reply made from this cache's field; counted in stats().
  KeptFrames& kept_frames() { return frames_; }
  void count_frames(int64_t made, int64_t kept) { stats_.frames += made, stats_.frames_kept += kept; }

  const FieldCacheStats& stats() const { return stats_; }

 private:
  struct Key {
    CellBox box;
    int pad = 0;
    UnknownAs unknown = UnknownAs::kFree;
    double resolution = 0;
  };
  static Key key_of(const CellBox& box, const DistanceOptions& opt, double resolution);
  static bool same_key(const Key& a, const Key& b, bool with_box);
  // Both updates' end, once grid_ is the new grid: the field kept (`any` false: no cell
  // changed), transformed over the reach of `changed` (the entry's field is for grid_'s box
  // and options before the change, `reuse`) or computed whole; then the entry is `key` at
  // `version`. `bring_grid(was_valid)` brings grid_ up to date and says whether (and where) cells
  // changed.
  struct Change {
    bool reuse = false, any = false;
    IndexBox box;
  };
  template <class BringGrid>
  const DistanceField& settle(const Key& key, uint64_t version, const SquaredEdt& edt, const DistanceOptions& opt,
                              BringGrid&& change);

  bool valid_ = false;
  Key key_;
  uint64_t version_ = 0;
  OccupancyGrid grid_;
  DistanceField field_;
  bool pending_valid_ = false;
  Key pending_key_;
  uint64_t pending_version_ = 0;
  std::optional<Memo> memo_;
  KeptFrames frames_;
  FieldCacheStats stats_;
};

}  // namespace ort::distance
