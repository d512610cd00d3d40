#include "daemon/queries/query_footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ort::daemon {
namespace {

using octomap::OcTreeKey;

query::KeyBox key_of(const OcTreeKey& k) { return query::KeyBox{k, k}; }

query::KeyBox region_box(const RegionGrid& grid, RegionId id) {
  return query::KeyBox{region_min_key(grid, id), region_max_key(grid, id)};
}

// The regions a segment passes, in key units (continuous: key k covers [k, k + 1)), by
// Amanatides and Woo's walk over cells of side_keys keys.
void ray_regions(const octomap::OcTree& tree, const RegionGrid& grid, const octomap::point3d& origin,
                 octomap::point3d dir, double range, std::vector<query::KeyBox>& out) {
  const double n = dir.norm();
  if (!(n > 0) || !std::isfinite(n)) return;
  dir /= static_cast<float>(n);
  const double res = tree.getResolution(), side = grid.side_keys(), top = 65536.0;
  double u[3], d[3];
  for (int a = 0; a < 3; ++a) {
    u[a] = origin(a) / res + 32768.0;
    d[a] = dir(a) / res;                                          // key units per metre
    if (!std::isfinite(u[a]) || u[a] < 0 || u[a] >= top) return;  // the answer is "outside the map"
  }
  // In metres along the ray: to its range, or to where it leaves the key range.
  double t_end = range > 0 ? range : std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
    if (d[a] != 0) t_end = std::min(t_end, ((d[a] > 0 ? top : 0.0) - u[a]) / d[a]);
  long cell[3], last[3], step[3];
  double t_next[3], t_delta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = static_cast<long>(std::floor(u[a] / side));
    const double end = std::clamp(u[a] + d[a] * t_end, 0.0, top - 1e-6);
    last[a] = static_cast<long>(std::floor(end / side));
    step[a] = d[a] > 0 ? 1 : d[a] < 0 ? -1 : 0;
    const double edge = (cell[a] + (step[a] > 0 ? 1 : 0)) * side;
    t_delta[a] = step[a] ? side / std::abs(d[a]) : std::numeric_limits<double>::infinity();
    t_next[a] = step[a] ? (edge - u[a]) / d[a] : std::numeric_limits<double>::infinity();
  }
  const long max_cells = 3 * (long(top / side) + 1);
  for (long i = 0; i < max_cells; ++i) {
    const OcTreeKey k(static_cast<uint16_t>(cell[0] * long(side)), static_cast<uint16_t>(cell[1] * long(side)),
                      static_cast<uint16_t>(cell[2] * long(side)));
    out.push_back(region_box(grid, region_of(grid, k)));
    if (cell[0] == last[0] && cell[1] == last[1] && cell[2] == last[2]) return;
    const int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    if (t_next[a] > t_end) return;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] * long(side) >= long(top)) return;
    t_next[a] += t_delta[a];
  }
}

// A distance query reads its box, points or path grown by the clamp distance and one cell
// (distance/occupancy_grid.h's padding); one cell more for the cells' alignment.
void distance_regions(const octomap::OcTree& tree, const octomap_rt::distance_query_t& q,
                      std::vector<query::KeyBox>& out) {
  using DQ = octomap_rt::distance_query_t;
  const int cell = q.mode == DQ::MODE_BOX ? std::max(1, q.cell_voxels) : 1;
  const double pad = q.max_distance + 2.0 * cell * tree.getResolution();
  auto grown = [&](const double lo[3], const double hi[3]) {
    const double a[3] = {lo[0] - pad, lo[1] - pad, lo[2] - pad}, b[3] = {hi[0] + pad, hi[1] + pad, hi[2] + pad};
    out.push_back(query::key_box(tree, a, b));
  };
  if (q.mode == DQ::MODE_BOX) return grown(q.box_min, q.box_max);
  const size_t n = q.xyz.size() / 3;
  for (size_t i = 0; i < n; ++i) {
    // Points: each its own; a path: each segment's bounding box (a lone vertex: itself).
    const size_t j = q.mode == DQ::MODE_PATH && i + 1 < n ? i + 1 : i;
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(q.xyz[3 * i + a], q.xyz[3 * j + a]);
      hi[a] = std::max(q.xyz[3 * i + a], q.xyz[3 * j + a]);
    }
    grown(lo, hi);
  }
}

}  // namespace

std::vector<query::KeyBox> query_footprint(const octomap::OcTree& tree, const RegionGrid& grid, const QueryMessage& q) {
  std::vector<query::KeyBox> out;
  try {
    if (auto* p = std::get_if<octomap_rt::occupancy_query_t>(&q)) {
      for (size_t i = 0; i + 2 < p->xyz.size(); i += 3) {
        OcTreeKey k;
        if (tree.coordToKeyChecked(octomap::point3d(p->xyz[i], p->xyz[i + 1], p->xyz[i + 2]), k))
          out.push_back(key_of(k));
      }
    } else if (auto* r = std::get_if<octomap_rt::ray_query_t>(&q)) {
      for (size_t i = 0; i + 2 < r->origin_xyz.size() && i + 2 < r->direction_xyz.size(); i += 3)
        ray_regions(tree, grid, octomap::point3d(r->origin_xyz[i], r->origin_xyz[i + 1], r->origin_xyz[i + 2]),
                    octomap::point3d(r->direction_xyz[i], r->direction_xyz[i + 1], r->direction_xyz[i + 2]),
                    r->max_range, out);
    } else if (auto* b = std::get_if<octomap_rt::box_query_t>(&q)) {
      for (size_t i = 0; i + 5 < b->boxes.size(); i += 6)
        out.push_back(query::key_box(tree, &b->boxes[i], &b->boxes[i + 3]));
    } else if (auto* g = std::get_if<octomap_rt::grid_query_t>(&q)) {
      const double big = 32768.0 * tree.getResolution();
      const double lo[3] = {g->use_window ? g->window_min[0] : -big, g->use_window ? g->window_min[1] : -big, g->z_min};
      const double hi[3] = {g->use_window ? g->window_max[0] : big, g->use_window ? g->window_max[1] : big, g->z_max};
      out.push_back(query::key_box(tree, lo, hi));
    } else if (auto* d = std::get_if<octomap_rt::distance_query_t>(&q)) {
      distance_regions(tree, *d, out);
    } else {  // a kind of query this file does not know yet: all of the map, to be safe
      out.push_back(query::KeyBox{OcTreeKey(0, 0, 0), OcTreeKey(65535, 65535, 65535)});
    }
  } catch (const std::exception&) {  // query::QueryError: answered as a refusal, reading nothing
    out.clear();
  }
  return out;
}

}  // namespace ort::daemon
