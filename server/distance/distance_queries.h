// The three distance queries (points, a dense box, a path) as two steps each: read_* copies
// what the answer needs out of the map (under the caller's shared map lock: bounded by
// DistanceLimits), answer_* runs the EDT and reads the field (no map, no lock). Every bound
// that refuses a request throws DistanceError saying which bound and by how much.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <octomap/OcTree.h>

#include "distance/distance_field.h"
#include "distance/distance_types.h"
#include "distance/occupancy_grid.h"

namespace ort::distance {

struct DistanceLimits {
  int64_t max_grid_cells = 32'000'000;    // padded cells read and transformed per request, all grids
  int64_t max_box_cells = 8'000'000;      // cells of a dense box answer
  int64_t max_path_samples = 100'000;     // samples of a path
  double max_distance = 10.0;             // [m] largest max_distance taken
  int max_padding_cells = 200;            // largest padding max_distance may ask for
  int64_t single_grid_cells = 8'000'000;  // points whose one grid would be larger go by blocks
};

// "" if the options are usable with this map and these limits, else why not.
std::string check_options(const DistanceOptions& opt, double resolution, const DistanceLimits& lim);

// --- points ---------------------------------------------------------------------------
struct PointDistance {
  float distance = 0;                  // [m], clamped at max_distance
  std::array<float, 3> gradient{};     // distance_field.h
  std::array<float, 3> cell_center{};  // [m] the centre the distance is measured from
};
struct PointsRead {
  DistanceOptions opt;
  double resolution = 0;
  std::vector<OccupancyGrid> grids;  // one around all points, or one per block of them
  struct Cell {
    int grid = 0;
    std::array<int64_t, 3> index{};  // in its grid
  };
  std::vector<Cell> cells;  // per point
};
// A box (field_cache.h's covering) to take as the points' one grid when it holds their padded
// cells; it answers the same (its extra obstacles are at least a padding away). `read`: read it
// from the map; else the caller brings its grid (the grid is left empty: the field cache's,
// brought up to date from the map's change lists).
struct GridCover {
  CellBox box;
  bool read = true;
};
using CoverFn = std::function<std::optional<GridCover>(const CellBox& want)>;
// xyz: 3 floats a point. Throws DistanceError (a point outside the key range, too many cells).
PointsRead read_points(const octomap::OcTree& tree, std::span<const float> xyz, const DistanceOptions& opt,
                       const DistanceLimits& lim);
PointsRead read_points(const octomap::OcTree& tree, std::span<const float> xyz, const DistanceOptions& opt,
                       const DistanceLimits& lim, const CoverFn& cover);
std::vector<PointDistance> answer_points(const PointsRead& read, const SquaredEdt& edt);
// The same from fields already computed, one per grid of `read` (in order).
std::vector<PointDistance> answer_points(const PointsRead& read, std::span<const DistanceField* const> fields);

// --- a dense box -------------------------------------------------------------------------
struct BoxRead {
  DistanceOptions opt;
  double resolution = 0;
  CellBox cells;       // the requested cells
  OccupancyGrid grid;  // cells grown by padding_cells
  int pad = 0;
};
BoxRead read_box(const octomap::OcTree& tree, const double lo[3], const double hi[3], const DistanceOptions& opt,
                 const DistanceLimits& lim);
// The same checked and sized, its grid not read (grid.box set, grid.occupied empty).
BoxRead plan_box(const octomap::OcTree& tree, const double lo[3], const double hi[3], const DistanceOptions& opt,
                 const DistanceLimits& lim);
struct BoxDistances {
  CellBox cells;
  double cell_size = 0, max_distance = 0;
  std::array<double, 3> origin{};  // [m] min corner of cell (0, 0, 0)
  // Per cell (x fastest): squared distance in cell units, kNoObstacle where it is beyond
  // max_distance (the clamp), so clamped_distance() of it is the cell's distance.
  std::vector<uint32_t> squared;
  std::vector<float> gradient;  // 3 per cell when asked for, else empty
};
// [m] the min corner of the box's cell (0, 0, 0) (BoxDistances::origin).
std::array<double, 3> box_origin(const BoxRead& read);
BoxDistances answer_box(const BoxRead& read, const SquaredEdt& edt, bool with_gradient);
// The same from the field of read.grid already computed (field_cache.h).
BoxDistances answer_box(const BoxRead& read, const DistanceField& field, bool with_gradient);

// --- a path ------------------------------------------------------------------------------
struct PathRead {
  PointsRead points;               // the samples
  std::vector<double> arc_length;  // [m] along the polyline, per sample
  std::vector<std::array<float, 3>> samples;
};
// vertices: 3 doubles a vertex (>= 1 vertex); samples every resolution along each segment.
PathRead read_path(const octomap::OcTree& tree, std::span<const double> vertices, const DistanceOptions& opt,
                   const DistanceLimits& lim, const CoverFn& cover = {});
struct PathClearance {
  float min_distance = 0;
  int64_t min_sample = 0;
  std::array<float, 3> min_point{};  // the sample where the minimum is (first one if tied)
  double min_arc_length = 0;
  int64_t num_samples = 0;
};
PathClearance answer_path(const PathRead& read, const SquaredEdt& edt);
// The clearance from the samples' distances (answer_points of read.points, in order).
PathClearance path_clearance(const PathRead& read, const std::vector<PointDistance>& samples);

}  // namespace ort::distance
