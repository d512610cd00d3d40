#include "scene/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ort::scene {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Entry distance of the ray into the box within [t_min, t_max], or kInf.
double hit_box(const Box& b, const Vec3& o, const Vec3& inv, double t_min, double t_max) {
  for (int i = 0; i < 3; ++i) {
    if (std::isinf(inv[i])) {  // parallel to this slab
      if (o[i] < b.lo[i] || o[i] > b.hi[i]) return kInf;
      continue;
    }
    double ta = (b.lo[i] - o[i]) * inv[i], tb = (b.hi[i] - o[i]) * inv[i];
    if (ta > tb) std::swap(ta, tb);
    t_min = std::max(t_min, ta);
    t_max = std::min(t_max, tb);
    if (t_min > t_max) return kInf;
  }
  return t_min;
}

// Clips the ray to the box [lo, hi]; false when it misses.
bool clip_to_bounds(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv, double& t0, double& t1) {
  const double t = hit_box(Box{lo, hi}, o, inv, t0, t1);
  if (t == kInf) return false;
  // exit distance
  double te = t1;
  for (int i = 0; i < 3; ++i) {
    if (std::isinf(inv[i])) continue;
    const double ta = (lo[i] - o[i]) * inv[i], tb = (hi[i] - o[i]) * inv[i];
    te = std::min(te, std::max(ta, tb));
  }
  t0 = t;
  t1 = te;
  return true;
}

Vec3 inverse(const Vec3& d) {
  auto inv = [](double v) { return v == 0.0 ? kInf : 1.0 / v; };
  return {inv(d.x), inv(d.y), inv(d.z)};
}

// Amanatides & Woo grid walk from distance t0; calls visit(x, y, z, t_exit) for each cell
// until it returns true or the walk leaves the grid or passes t_end.
template <class Visit>
void walk_cells(const Vec3& lo, double cell, const int dims[3], const Vec3& o, const Vec3& d, const Vec3& inv,
                double t0, double t_end, Visit&& visit) {
  int idx[3], step[3];
  double t_next[3], t_delta[3];
  for (int i = 0; i < 3; ++i) {
    const double p = o[i] + d[i] * t0;
    int c = int(std::floor((p - lo[i]) / cell));
    idx[i] = std::clamp(c, 0, dims[i] - 1);
    if (d[i] > 0) {
      step[i] = 1;
      t_delta[i] = cell * inv[i];
      t_next[i] = (lo[i] + (idx[i] + 1) * cell - o[i]) * inv[i];
    } else if (d[i] < 0) {
      step[i] = -1;
      t_delta[i] = -cell * inv[i];
      t_next[i] = (lo[i] + idx[i] * cell - o[i]) * inv[i];
    } else {
      step[i] = 0;
      t_delta[i] = kInf;
      t_next[i] = kInf;
    }
  }
  for (;;) {
    const int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    const double t_exit = t_next[a];
    if (visit(idx[0], idx[1], idx[2], t_exit)) return;
    if (t_exit > t_end) return;
    idx[a] += step[a];
    if (idx[a] < 0 || idx[a] >= dims[a]) return;
    t_next[a] += t_delta[a];
  }
}

}  // namespace

BoxGrid build_box_grid(std::vector<Box> boxes, double cell) {
  BoxGrid g;
  g.boxes = std::move(boxes);
  if (g.boxes.empty()) return g;
  g.lo = g.boxes[0].lo;
  g.hi = g.boxes[0].hi;
  for (const Box& b : g.boxes) {
    g.lo = {std::min(g.lo.x, b.lo.x), std::min(g.lo.y, b.lo.y), std::min(g.lo.z, b.lo.z)};
    g.hi = {std::max(g.hi.x, b.hi.x), std::max(g.hi.y, b.hi.y), std::max(g.hi.z, b.hi.z)};
  }
  g.lo = g.lo - Vec3{0.01, 0.01, 0.01};
  g.hi = g.hi + Vec3{0.01, 0.01, 0.01};
  const Vec3 ext = g.hi - g.lo;
  // Keep the cell table small (a few MB) whatever the scene's extent.
  const double min_cell = std::cbrt(ext.x * ext.y * ext.z / 4.0e6);
  g.cell = std::max(cell, min_cell);
  for (int i = 0; i < 3; ++i) g.dims[i] = std::max(1, int(std::ceil(ext[i] / g.cell)));
  const size_t ncells = size_t(g.dims[0]) * g.dims[1] * g.dims[2];

  auto cell_range = [&](const Box& b, int lo[3], int hi[3]) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::clamp(int(std::floor((b.lo[i] - g.lo[i]) / g.cell)), 0, g.dims[i] - 1);
      hi[i] = std::clamp(int(std::floor((b.hi[i] - g.lo[i]) / g.cell)), 0, g.dims[i] - 1);
    }
  };
  std::vector<uint32_t> count(ncells + 1, 0);
  int lo[3], hi[3];
  for (const Box& b : g.boxes) {
    cell_range(b, lo, hi);
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) ++count[(size_t(z) * g.dims[1] + y) * g.dims[0] + x + 1];
  }
  for (size_t c = 0; c < ncells; ++c) count[c + 1] += count[c];
  g.cell_start = count;
  g.box_index.resize(count[ncells]);
  for (uint32_t bi = 0; bi < g.boxes.size(); ++bi) {
    cell_range(g.boxes[bi], lo, hi);
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) g.box_index[count[(size_t(z) * g.dims[1] + y) * g.dims[0] + x]++] = bi;
  }
  return g;
}

double cast_ray(const BoxGrid& g, const Vec3& o, const Vec3& d, double max_t) {
  if (g.boxes.empty()) return kInf;
  const Vec3 inv = inverse(d);
  double t0 = 0.0, t1 = max_t;
  if (!clip_to_bounds(g.lo, g.hi, o, inv, t0, t1)) return kInf;
  double best = kInf;
  walk_cells(g.lo, g.cell, g.dims, o, d, inv, t0, t1, [&](int x, int y, int z, double t_exit) {
    const size_t c = (size_t(z) * g.dims[1] + y) * g.dims[0] + x;
    for (uint32_t k = g.cell_start[c]; k < g.cell_start[c + 1]; ++k) {
      best = std::min(best, hit_box(g.boxes[g.box_index[k]], o, inv, 0.0, std::min(best, max_t)));
    }
    // A box hit inside this cell (or nearer) cannot be beaten by a box in a later cell.
    return best <= t_exit;
  });
  return best;
}

double cast_ray(const OccupancyGrid& g, const Vec3& o, const Vec3& d, double max_t) {
  if (g.bits.empty()) return kInf;
  const Vec3 inv = inverse(d);
  const Vec3 hi = g.lo + Vec3{g.dims[0] * g.voxel, g.dims[1] * g.voxel, g.dims[2] * g.voxel};
  double t0 = 0.0, t1 = max_t;
  if (!clip_to_bounds(g.lo, hi, o, inv, t0, t1)) return kInf;
  double hit = kInf, t_entry = t0;
  walk_cells(g.lo, g.voxel, g.dims, o, d, inv, t0, t1, [&](int x, int y, int z, double t_exit) {
    if (g.occupied(x, y, z)) {
      hit = t_entry;
      return true;
    }
    t_entry = t_exit;
    return false;
  });
  return hit;
}

double cast_ray(const Scene& s, const Vec3& o, const Vec3& d, double max_t) {
  return s.use_grid ? cast_ray(s.grid, o, d, max_t) : cast_ray(s.boxes, o, d, max_t);
}

bool inside_solid(const Scene& s, const Vec3& p, double margin) {
  if (s.use_grid) {
    const OccupancyGrid& g = s.grid;
    const int r = int(std::ceil(margin / g.voxel));
    const int cx = int(std::floor((p.x - g.lo.x) / g.voxel)), cy = int(std::floor((p.y - g.lo.y) / g.voxel)),
              cz = int(std::floor((p.z - g.lo.z) / g.voxel));
    for (int z = cz - r; z <= cz + r; ++z)
      for (int y = cy - r; y <= cy + r; ++y)
        for (int x = cx - r; x <= cx + r; ++x) {
          if (x < 0 || y < 0 || z < 0 || x >= g.dims[0] || y >= g.dims[1] || z >= g.dims[2]) continue;
          if (g.occupied(x, y, z)) return true;
        }
    return false;
  }
  for (const Box& b : s.boxes.boxes) {
    if (p.x > b.lo.x - margin && p.x < b.hi.x + margin && p.y > b.lo.y - margin && p.y < b.hi.y + margin &&
        p.z > b.lo.z - margin && p.z < b.hi.z + margin)
      return true;
  }
  return false;
}

}  // namespace ort::scene
