#include "distance/distance_queries.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

namespace ort::distance {
namespace {

constexpr int64_t kKeyOrigin = 32768;  // OcTree's tree_max_val: key of coordinate 0
constexpr int64_t kBlockCells = 32;    // block side [cells] for spread-out points

std::string num(double v) {
  std::string s = std::to_string(v);
  return s.substr(0, s.find_last_not_of('0') + 1);
}

// The finest key of a coordinate, false outside the key range (NaN too).
bool key_of(const octomap::OcTree& tree, double c, int64_t& key) {
  const double far = tree.getResolution() * double(kKeyOrigin);
  if (!(std::abs(c) < far)) return false;
  octomap::key_type k = 0;
  if (!tree.coordToKeyChecked(c, k)) return false;
  key = k;
  return true;
}

std::array<int64_t, 3> cell_index(const std::array<int64_t, 3>& key, const CellBox& box) {
  std::array<int64_t, 3> idx{};
  for (int a = 0; a < 3; ++a) idx[a] = (key[a] / box.cell_voxels * box.cell_voxels - box.key_lo[a]) / box.cell_voxels;
  return idx;
}

void check_cells(int64_t cells, const DistanceLimits& lim) {
  if (cells > lim.max_grid_cells)
    throw DistanceError("the request needs " + std::to_string(cells) + " padded cells (at most " +
                        std::to_string(lim.max_grid_cells) + "): ask for fewer or closer points, a smaller box, " +
                        "a smaller max_distance or a coarser cell");
}

}  // namespace

std::string check_options(const DistanceOptions& opt, double resolution, const DistanceLimits& lim) {
  if (!std::isfinite(opt.max_distance) || !(opt.max_distance > 0) || opt.max_distance > lim.max_distance)
    return "max_distance must be in (0, " + num(lim.max_distance) + "] m";
  if (opt.cell_voxels < 1 || opt.cell_voxels > kMaxCellVoxels)
    return "cell_voxels must be in 1.." + std::to_string(kMaxCellVoxels);
  if (opt.unknown != UnknownAs::kFree && opt.unknown != UnknownAs::kOccupied) return "unknown_as must be 0 or 1";
  if (padding_cells(opt, resolution) > lim.max_padding_cells)
    return "max_distance " + num(opt.max_distance) + " m is " + std::to_string(padding_cells(opt, resolution)) +
           " cells of " + num(resolution * opt.cell_voxels) + " m (at most " + std::to_string(lim.max_padding_cells) +
           "): use a coarser cell or a smaller max_distance";
  return "";
}

PointsRead read_points(const octomap::OcTree& tree, std::span<const float> xyz, const DistanceOptions& opt,
                       const DistanceLimits& lim) {
  return read_points(tree, xyz, opt, lim, {});
}

PointsRead read_points(const octomap::OcTree& tree, std::span<const float> xyz, const DistanceOptions& opt,
                       const DistanceLimits& lim, const CoverFn& cover) {
  PointsRead r;
  r.opt = opt;
  r.resolution = tree.getResolution();
  if (std::string bad = check_options(opt, r.resolution, lim); !bad.empty()) throw DistanceError(bad);
  const size_t n = xyz.size() / 3;
  if (n == 0) return r;
  const int m = opt.cell_voxels, pad = padding_cells(opt, r.resolution);
  std::vector<std::array<int64_t, 3>> keys(n);
  std::array<int64_t, 3> lo{}, hi{};
  for (size_t p = 0; p < n; ++p) {
    for (int a = 0; a < 3; ++a)
      if (!key_of(tree, xyz[3 * p + a], keys[p][a]))
        throw DistanceError("point " + std::to_string(p) + " is outside the map's key range");
    for (int a = 0; a < 3; ++a)
      lo[a] = p ? std::min(lo[a], keys[p][a]) : keys[p][a], hi[a] = p ? std::max(hi[a], keys[p][a]) : keys[p][a];
  }
  r.cells.resize(n);
  const CellBox all = cell_box_around(lo, hi, m, pad);
  if (const std::optional<GridCover> c = cover ? cover(all) : std::nullopt; c) {
    check_cells(c->box.dims.cells(), lim);
    r.grids.push_back(c->read ? read_occupancy(tree, c->box, opt.unknown, opt.ownership) : OccupancyGrid{c->box, {}});
    for (size_t p = 0; p < n; ++p) r.cells[p] = {0, cell_index(keys[p], c->box)};
    return r;
  }
  if (all.dims.cells() <= std::min(lim.single_grid_cells, lim.max_grid_cells)) {
    r.grids.push_back(read_occupancy(tree, all, opt.unknown, opt.ownership));
    for (size_t p = 0; p < n; ++p) r.cells[p] = {0, cell_index(keys[p], all)};
    return r;
  }
  // Spread out: one grid per block of kBlockCells cells that holds points, around its points.
  std::map<std::array<int64_t, 3>, std::vector<size_t>> blocks;
  for (size_t p = 0; p < n; ++p) {
    std::array<int64_t, 3> b{};
    for (int a = 0; a < 3; ++a) b[a] = keys[p][a] / m / kBlockCells;
    blocks[b].push_back(p);
  }
  std::vector<std::pair<CellBox, const std::vector<size_t>*>> boxes;
  int64_t cells = 0;
  for (const auto& [block, points] : blocks) {
    std::array<int64_t, 3> blo = keys[points[0]], bhi = keys[points[0]];
    for (size_t p : points)
      for (int a = 0; a < 3; ++a) blo[a] = std::min(blo[a], keys[p][a]), bhi[a] = std::max(bhi[a], keys[p][a]);
    boxes.emplace_back(cell_box_around(blo, bhi, m, pad), &points);
    cells += boxes.back().first.dims.cells();
  }
  check_cells(cells, lim);
  for (const auto& [box, points] : boxes) {
    for (size_t p : *points) r.cells[p] = {static_cast<int>(r.grids.size()), cell_index(keys[p], box)};
    r.grids.push_back(read_occupancy(tree, box, opt.unknown, opt.ownership));
  }
  return r;
}

std::vector<PointDistance> answer_points(const PointsRead& r, const SquaredEdt& edt) {
  std::vector<DistanceField> fields;
  for (const OccupancyGrid& g : r.grids) fields.push_back(compute_field(g, edt, r.resolution, r.opt));
  std::vector<const DistanceField*> each;
  for (const DistanceField& f : fields) each.push_back(&f);
  return answer_points(r, each);
}

std::vector<PointDistance> answer_points(const PointsRead& r, std::span<const DistanceField* const> fields) {
  if (fields.size() != r.grids.size()) throw std::logic_error("answer_points: one field per grid");
  std::vector<PointDistance> out(r.cells.size());
  for (size_t p = 0; p < r.cells.size(); ++p) {
    const DistanceField& f = *fields[size_t(r.cells[p].grid)];
    const auto& [i, j, k] = r.cells[p].index;
    out[p].distance = f.distance(i, j, k);
    out[p].gradient = f.gradient(i, j, k);
    const int64_t idx[3] = {i, j, k};
    for (int a = 0; a < 3; ++a)
      out[p].cell_center[a] = static_cast<float>(
          (double(f.box.key_lo[a] + idx[a] * f.box.cell_voxels - kKeyOrigin) + 0.5 * f.box.cell_voxels) * r.resolution);
  }
  return out;
}

BoxRead read_box(const octomap::OcTree& tree, const double lo[3], const double hi[3], const DistanceOptions& opt,
                 const DistanceLimits& lim) {
  BoxRead r = plan_box(tree, lo, hi, opt, lim);
  r.grid = read_occupancy(tree, r.grid.box, opt.unknown, opt.ownership);
  return r;
}

BoxRead plan_box(const octomap::OcTree& tree, const double lo[3], const double hi[3], const DistanceOptions& opt,
                 const DistanceLimits& lim) {
  BoxRead r;
  r.opt = opt;
  r.resolution = tree.getResolution();
  if (std::string bad = check_options(opt, r.resolution, lim); !bad.empty()) throw DistanceError(bad);
  std::array<int64_t, 3> klo{}, khi{};
  for (int a = 0; a < 3; ++a) {
    if (!(lo[a] <= hi[a])) throw DistanceError("box min > max (or not finite)");
    if (!key_of(tree, lo[a], klo[a]) || !key_of(tree, hi[a], khi[a]))
      throw DistanceError("a box corner is outside the map's key range");
  }
  r.pad = padding_cells(opt, r.resolution);
  r.cells = cell_box_around(klo, khi, opt.cell_voxels, 0);
  if (r.cells.dims.cells() > lim.max_box_cells)
    throw DistanceError("the box has " + std::to_string(r.cells.dims.cells()) + " cells (at most " +
                        std::to_string(lim.max_box_cells) + "): ask for a smaller box or a coarser cell");
  const CellBox padded = cell_box_around(klo, khi, opt.cell_voxels, r.pad);
  check_cells(padded.dims.cells(), lim);
  r.grid.box = padded;
  return r;
}

std::array<double, 3> box_origin(const BoxRead& r) {
  std::array<double, 3> o{};
  for (int a = 0; a < 3; ++a) o[a] = double(r.cells.key_lo[a] - kKeyOrigin) * r.resolution;
  return o;
}

BoxDistances answer_box(const BoxRead& r, const SquaredEdt& edt, bool with_gradient) {
  return answer_box(r, compute_field(r.grid, edt, r.resolution, r.opt), with_gradient);
}

BoxDistances answer_box(const BoxRead& r, const DistanceField& f, bool with_gradient) {
  if (f.box.dims.nx != r.cells.dims.nx + 2 * r.pad || f.box.dims.ny != r.cells.dims.ny + 2 * r.pad ||
      f.box.dims.nz != r.cells.dims.nz + 2 * r.pad)
    throw std::logic_error("answer_box: the field is not of the box's padded grid");
  BoxDistances b;
  b.cells = r.cells;
  b.cell_size = f.cell_size;
  b.max_distance = f.max_distance;
  b.origin = box_origin(r);
  const GridDims d = r.cells.dims;
  b.squared.resize(size_t(d.cells()));
  if (with_gradient) b.gradient.resize(3 * size_t(d.cells()));
  const double max_sq = (f.max_distance / f.cell_size) * (f.max_distance / f.cell_size);
  size_t c = 0;
  for (int64_t k = 0; k < d.nz; ++k)
    for (int64_t j = 0; j < d.ny; ++j)
      for (int64_t i = 0; i < d.nx; ++i, ++c) {
        const uint32_t sq = f.squared[size_t(f.index(i + r.pad, j + r.pad, k + r.pad))];
        b.squared[c] = double(sq) > max_sq ? kNoObstacle : sq;
        if (!with_gradient) continue;
        const auto g = f.gradient(i + r.pad, j + r.pad, k + r.pad);
        std::copy(g.begin(), g.end(), b.gradient.begin() + 3 * c);
      }
  return b;
}

PathRead read_path(const octomap::OcTree& tree, std::span<const double> v, const DistanceOptions& opt,
                   const DistanceLimits& lim, const CoverFn& cover) {
  const size_t n = v.size() / 3;
  if (n == 0) throw DistanceError("a path needs at least one vertex");
  for (double x : v)
    if (!std::isfinite(x)) throw DistanceError("a path vertex is not finite");
  const double step = tree.getResolution();
  int64_t total = 1;
  std::vector<int64_t> steps(n, 0);
  for (size_t s = 0; s + 1 < n; ++s) {
    const double len = std::hypot(v[3 * s + 3] - v[3 * s], v[3 * s + 4] - v[3 * s + 1], v[3 * s + 5] - v[3 * s + 2]);
    const double k = std::ceil(len / step);
    if (k > double(lim.max_path_samples)) throw DistanceError("a path segment needs too many samples");
    steps[s] = std::max<int64_t>(1, int64_t(k));
    total += steps[s];
    if (total > lim.max_path_samples)
      throw DistanceError("the path needs more than " + std::to_string(lim.max_path_samples) + " samples at " +
                          num(step) + " m");
  }
  PathRead r;
  std::vector<float> xyz;
  double arc = 0;
  auto add = [&](double x, double y, double z, double a) {
    r.samples.push_back({float(x), float(y), float(z)});
    r.arc_length.push_back(a);
    xyz.insert(xyz.end(), {float(x), float(y), float(z)});
  };
  for (size_t s = 0; s + 1 < n; ++s) {
    const double* p = &v[3 * s];
    const double len = std::hypot(p[3] - p[0], p[4] - p[1], p[5] - p[2]);
    for (int64_t i = 0; i < steps[s]; ++i) {
      const double t = double(i) / double(steps[s]);
      add(p[0] + t * (p[3] - p[0]), p[1] + t * (p[4] - p[1]), p[2] + t * (p[5] - p[2]), arc + t * len);
    }
    arc += len;
  }
  add(v[3 * n - 3], v[3 * n - 2], v[3 * n - 1], arc);
  r.points = read_points(tree, xyz, opt, lim, cover);
  return r;
}

PathClearance answer_path(const PathRead& r, const SquaredEdt& edt) {
  return path_clearance(r, answer_points(r.points, edt));
}

PathClearance path_clearance(const PathRead& r, const std::vector<PointDistance>& d) {
  PathClearance c;
  c.num_samples = static_cast<int64_t>(d.size());
  for (size_t i = 0; i < d.size(); ++i)
    if (i == 0 || d[i].distance < c.min_distance) {
      c.min_distance = d[i].distance;
      c.min_sample = static_cast<int64_t>(i);
    }
  if (!d.empty()) c.min_point = r.samples[size_t(c.min_sample)], c.min_arc_length = r.arc_length[size_t(c.min_sample)];
  return c;
}

}  // namespace ort::distance
