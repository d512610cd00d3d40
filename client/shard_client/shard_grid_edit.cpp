#include "shard_client/shard_grid_edit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "shard_client/shard_ask.h"
#include "shard_client/shard_distance.h"
#include "shard_client/shard_queries.h"

namespace ort::client {

Grid merge_grids(const std::vector<const Grid*>& got) {
  const Grid* base = nullptr;
  int64_t i0 = 0, j0 = 0, i1 = 0, j1 = 0;  // the union, in cells from the key origin
  for (const Grid* g : got) {
    if (!g || g->header.status != octomap_rt::occupancy_reply_t::REPLY_OK) continue;
    const double c = g->header.cell_size;
    if (base && c != base->header.cell_size) throw std::invalid_argument("the shards' grids differ in cell size");
    const int64_t gi = std::llround(g->header.origin_x / c), gj = std::llround(g->header.origin_y / c);
    i0 = base ? std::min(i0, gi) : gi, j0 = base ? std::min(j0, gj) : gj;
    i1 = base ? std::max(i1, gi + g->header.width) : gi + g->header.width;
    j1 = base ? std::max(j1, gj + g->header.height) : gj + g->header.height;
    if (!base) base = g;
  }
  Grid out;
  if (!base) {
    out.header.status = octomap_rt::occupancy_reply_t::REPLY_BAD_REQUEST;
    out.header.error = "no shard answered";
    return out;
  }
  out.header = base->header;
  const double c = base->header.cell_size;
  out.header.width = int32_t(i1 - i0), out.header.height = int32_t(j1 - j0);
  out.header.origin_x = double(i0) * c, out.header.origin_y = double(j0) * c;
  out.header.num_chunks = 0, out.header.chunk_index = 0, out.header.row_start = 0, out.header.num_rows = 0;
  out.cells.assign(size_t(out.header.width) * size_t(out.header.height), octomap_rt::occupancy_reply_t::OCC_UNKNOWN);
  for (const Grid* g : got) {
    if (!g || g->header.status != octomap_rt::occupancy_reply_t::REPLY_OK) continue;
    out.header.utime = std::max(out.header.utime, g->header.utime);
    out.header.snapshot_id = std::max(out.header.snapshot_id, g->header.snapshot_id);
    out.header.map_utime = std::max(out.header.map_utime, g->header.map_utime);
    out.header.num_chunks += g->header.num_chunks;
    const int64_t di = std::llround(g->header.origin_x / c) - i0, dj = std::llround(g->header.origin_y / c) - j0;
    for (int32_t j = 0; j < g->header.height; ++j)
      for (int32_t i = 0; i < g->header.width; ++i) {
        int8_t& cell = out.cells[size_t(j + dj) * out.header.width + size_t(i + di)];
        cell = std::max(cell, g->cells[size_t(j) * g->header.width + size_t(i)]);  // OCC_* ordered
      }
  }
  return out;
}

Routed<Grid> ShardQueries::grid(double z_min, double z_max, double cell_size, const Box* window, const ShardWait& w) {
  std::vector<uint32_t> which = detail::every_shard(set_.count);
  if (window) {  // only the shards owning a region the window's columns in the band meet
    const double lo[3] = {window->min[0], window->min[1], z_min}, hi[3] = {window->max[0], window->max[1], z_max};
    std::array<int64_t, 3> klo{}, khi{};
    bool inside = true;
    for (int a = 0; a < 3; ++a)
      inside = inside && voxel_key(lo[a], resolution_, klo[a]) && voxel_key(hi[a], resolution_, khi[a]);
    if (inside) which = shards_meeting(set_, klo, khi);
    if (which.empty()) which = {0};
  }
  Routed<Grid> out;
  const auto got = detail::ask_each<Grid>(which, set_.count, out.shards, [&](uint32_t i) {
    return clients_[i]->grid(z_min, z_max, cell_size, window, w.on_shard(i));
  });
  std::vector<const Grid*> views;
  for (const auto& g : got) views.push_back(g ? &*g : nullptr);
  out.reply = merge_grids(views);
  return out;
}

Routed<octomap_rt::map_edit_ack_t> ShardQueries::edit(int8_t op, const Box& box, const std::string& token,
                                                      int8_t flags) {
  using Edit = octomap_rt::map_edit_t;
  if (flags & Edit::FLAG_INCLUDE_UNKNOWN)
    throw std::invalid_argument(
        "a shard set does not mark unknown space free (--include-unknown): every shard refuses it");
  std::vector<uint32_t> which = detail::every_shard(set_.count);
  if (op != Edit::OP_RESET) {
    std::array<int64_t, 3> klo{}, khi{};
    bool inside = true;
    for (int a = 0; a < 3; ++a)
      inside = inside && voxel_key(std::max(box.min[a], -resolution_ * 32767.0), resolution_, klo[a]) &&
               voxel_key(std::min(box.max[a], resolution_ * 32767.0), resolution_, khi[a]);
    if (inside) which = shards_meeting(set_, klo, khi);
    if (which.empty()) which = detail::every_shard(set_.count);  // each refuses it alike
  }
  Routed<octomap_rt::map_edit_ack_t> out;
  const auto got = detail::ask_each<octomap_rt::map_edit_ack_t>(
      which, set_.count, out.shards, [&](uint32_t i) { return clients_[i]->edit(op, box, token, flags); });
  auto& r = out.reply;
  r.op = op;
  r.status = out.shards.missing.empty() ? octomap_rt::occupancy_reply_t::REPLY_OK
                                        : octomap_rt::occupancy_reply_t::REPLY_NOT_READY;
  r.error = out.shards.shortfall();
  for (const auto& g : got)
    if (g) {
      r.utime = std::max(r.utime, g->utime), r.snapshot_id = std::max(r.snapshot_id, g->snapshot_id);
      r.map_utime = std::max(r.map_utime, g->map_utime), r.voxels = g->voxels, r.request_id = g->request_id;
    }
  return out;
}

}  // namespace ort::client
