#include "daemon/queries/query_answers.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "daemon/queries/distance_answers.h"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "octomap_rt/region_chunk_t.hpp"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
#include "protocol/shards/shard_set.h"
#include "query/box_count.h"
#include "query/point_query.h"
#include "query/projected_grid.h"
#include "query/ray_query.h"
#include "query/region_extract.h"

namespace ort::daemon {
namespace {

using Reply = octomap_rt::occupancy_reply_t;
using Box = octomap_rt::box_query_t;
constexpr int kRegionChunk = protocol::kRegionChunkVoxels, kGridChunkCells = protocol::kGridChunkCells;
// A region voxel on the wire: state, depth and its center's three floats.
constexpr size_t kRegionVoxelBytes = 1 + 1 + 12;

EncodedReplies replies_on(const std::string& channel) {
  EncodedReplies out;
  out.channel = channel;
  return out;
}

template <class V>
bool all_finite(const V& v) {
  return std::all_of(v.begin(), v.end(), [](auto x) { return std::isfinite(x); });
}

std::string validate(const octomap_rt::occupancy_query_t& q, double) {
  if (q.num_xyz % 3) return "num_xyz is not a multiple of 3";
  if (!all_finite(q.xyz)) return "a point is not finite";
  if (q.depth < 0 || q.depth > 16) return "depth " + std::to_string(q.depth) + " is not in 0..16";
  return "";
}
std::string validate(const octomap_rt::ray_query_t& q, double) {
  if (q.num_xyz % 3) return "num_xyz is not a multiple of 3";
  if (!all_finite(q.origin_xyz) || !all_finite(q.direction_xyz)) return "a ray origin or direction is not finite";
  if (!std::isfinite(q.max_range) || q.max_range > 10000) return "max_range must be finite and <= 10000 m";
  if (q.ignore_unknown && !(q.max_range > 0))
    return "ignore_unknown needs max_range > 0 (else the ray walks to the edge of the key range)";
  for (size_t i = 0; i + 2 < q.direction_xyz.size(); i += 3)
    if (octomap::point3d(q.direction_xyz[i], q.direction_xyz[i + 1], q.direction_xyz[i + 2]).norm() < 1e-12f)
      return "ray " + std::to_string(i / 3) + " has a zero direction";
  return "";
}
std::string validate(const octomap_rt::box_query_t& q, double) {
  if (q.num_values % 6) return "num_values is not a multiple of 6";
  if (!all_finite(q.boxes)) return "a box corner is not finite";
  for (size_t i = 0; i + 5 < q.boxes.size(); i += 6)
    for (int a = 0; a < 3; ++a)
      if (q.boxes[i + a] > q.boxes[i + 3 + a]) return "box " + std::to_string(i / 6) + " has min > max";
  if (q.mode != Box::MODE_COUNTS && q.mode != Box::MODE_ANY_OCCUPIED && q.mode != Box::MODE_REGION)
    return "unknown mode " + std::to_string(q.mode);
  if (q.mode == Box::MODE_REGION && q.num_values != 6) return "MODE_REGION takes exactly one box";
  if (q.depth < 0 || q.depth > 16) return "depth " + std::to_string(q.depth) + " is not in 0..16";
  return "";
}
std::string validate(const octomap_rt::grid_query_t& q, double res) {
  const double v[] = {q.z_min,         q.z_max,         q.cell_size,    q.window_min[0],
                      q.window_min[1], q.window_max[0], q.window_max[1]};
  if (!std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); }))
    return "a number is not finite";
  if (q.z_min > q.z_max) return "z_min > z_max";
  if (q.cell_size < 0) return "cell_size < 0";
  const double k = q.cell_size / res;
  if (q.cell_size > 0 && (std::abs(k - std::round(k)) > 1e-6 || std::round(k) < 1 || k > 32768))
    return "cell_size must be a multiple of the resolution " + std::to_string(res);
  if (q.use_window && (q.window_min[0] > q.window_max[0] || q.window_min[1] > q.window_max[1]))
    return "window min > max";
  return "";
}

// Distance queries are checked by validate_distance, with the service's limits.
std::string validate(const octomap_rt::distance_query_t&, double) { return ""; }

EncodedReplies points(const octomap::OcTree& t, const octomap_rt::occupancy_query_t& q, const QueryHeader& h,
                      const MapStamp& s, const std::string& id) {
  const auto answers = query::query_points(t, std::span<const float>(q.xyz), q.depth);
  Reply r;
  stamp_reply(r, h, s, id, Reply::REPLY_OK, "");
  r.num_results = static_cast<int32_t>(answers.size());
  for (const query::PointAnswer& a : answers) {
    r.occupancy.push_back(static_cast<int8_t>(a.state));
    r.probability.push_back(a.probability);
  }
  EncodedReplies out = replies_on(h.reply_channel);
  out.messages.push_back(encode_message(r));
  return out;
}

// A reply that answers the first `done` of `asked` items: cut there when fewer, with why.
template <class M>
void mark_cut(M& r, EncodedReplies& out, size_t done, size_t asked, const char* item, const query::WorkBudget& b,
              const QueryBounds& bounds) {
  r.cut = Reply::CUT_NONE, r.cut_at = -1;
  if (done >= asked) return;
  r.cut = static_cast<int8_t>(b.cut), r.cut_at = static_cast<int32_t>(done);
  r.error = "cut at " + std::string(item) + " " + std::to_string(done) + " of " + std::to_string(asked) + ": " +
            cut_reason(b, bounds);
  out.cut = true, out.error = r.error;
}

// A region or grid past its bound is refused whole: BUSY when time ran out (it may fit
// another turn), BAD_REQUEST when its work never fits.
EncodedReplies refused_by_budget(const QueryMessage& q, const query::WorkBudget& b, const QueryBounds& bounds,
                                 const MapStamp& s, const std::string& id) {
  const int8_t status = b.cut == query::Cut::kWork ? Reply::REPLY_BAD_REQUEST : Reply::REPLY_BUSY;
  const std::string why = "refused: " + cut_reason(b, bounds) + "; ask for a smaller box or a coarser cell";
  EncodedReplies out = error_reply(q, status, why, s, id);
  out.status = status, out.error = why;
  return out;
}

EncodedReplies rays(const octomap::OcTree& t, const octomap_rt::ray_query_t& q, const QueryHeader& h, const MapStamp& s,
                    const std::string& id, const QueryBounds& bounds, query::WorkBudget& budget,
                    const protocol::ShardSet& shard) {
  query::RayBatchOptions opt;
  opt.ignore_unknown = q.ignore_unknown != 0;
  opt.max_range = q.max_range;
  if (shard.sharded())  // a shard's share of the walk: its own regions (PROTOCOL.md, "Shards")
    opt.owns = [&shard](const octomap::OcTreeKey& k) {
      return protocol::shard_of(shard, protocol::region_coords(shard.region_depth, k[0], k[1], k[2])) == shard.index;
    };
  const auto answers = query::cast_rays(t, q.origin_xyz, q.direction_xyz, opt, &budget);
  const size_t asked = q.origin_xyz.size() / 3;
  if (answers.empty() && asked > 0 && budget.cut == query::Cut::kWork)
    throw query::QueryError("ray 0 may walk " +
                            std::to_string(query::ray_walk_bound(
                                t, octomap::point3d(q.direction_xyz[0], q.direction_xyz[1], q.direction_xyz[2]), opt)) +
                            " keys, over the query's work bound of " + std::to_string(bounds.max_work) +
                            " (--query-max-work): give it a shorter max_range");
  octomap_rt::ray_reply_t r;
  EncodedReplies out = replies_on(h.reply_channel);
  stamp_reply(r, h, s, id, Reply::REPLY_OK, "");
  mark_cut(r, out, answers.size(), asked, "ray", budget, bounds);
  r.num_rays = static_cast<int32_t>(answers.size());
  for (const query::RayAnswer& a : answers) {
    r.hit.push_back(a.hit);
    r.end_state.push_back(static_cast<int8_t>(a.end_state));
    r.end_xyz.insert(r.end_xyz.end(), {a.end.x(), a.end.y(), a.end.z()});
  }
  r.num_xyz = static_cast<int32_t>(r.end_xyz.size());
  out.messages.push_back(encode_message(r));
  return out;
}

EncodedReplies box_counts(const octomap::OcTree& t, const octomap_rt::box_query_t& q, const QueryHeader& h,
                          const MapStamp& s, const std::string& id, const QueryBounds& bounds,
                          query::WorkBudget& budget) {
  octomap_rt::box_reply_t r;
  EncodedReplies out = replies_on(h.reply_channel);
  stamp_reply(r, h, s, id, Reply::REPLY_OK, "");
  for (size_t i = 0; i + 5 < q.boxes.size(); i += 6) {
    // A box the budget ran out in is not answered: its counts would be partial. The clock is
    // not read before the first box (as for rays: query/ray_query.cpp's cast_rays).
    if (i > 0 && !budget.check_now()) break;
    const query::KeyBox b = query::key_box(t, &q.boxes[i], &q.boxes[i + 3]);
    if (q.mode == Box::MODE_ANY_OCCUPIED) {
      const bool any = query::any_occupied(t, b, &budget);
      if (budget.cut != query::Cut::kNone && !any) break;
      r.occupied.push_back(-1), r.free.push_back(-1), r.unknown.push_back(-1);
      r.any_occupied.push_back(any);
    } else {
      const query::BoxCounts c = query::count_box(t, b, &budget);
      if (budget.cut != query::Cut::kNone) break;
      r.occupied.push_back(c.occupied), r.free.push_back(c.free), r.unknown.push_back(c.unknown);
      r.any_occupied.push_back(c.any_occupied());
    }
  }
  const size_t asked = q.boxes.size() / 6;
  if (r.occupied.empty() && asked > 0 && budget.cut != query::Cut::kNone) {
    if (budget.cut == query::Cut::kWork)
      throw query::QueryError("box 0 alone passes the query's work bound: " + cut_reason(budget, bounds));
    return refused_by_budget(QueryMessage(q), budget, bounds, s, id);
  }
  mark_cut(r, out, r.occupied.size(), asked, "box", budget, bounds);
  r.num_boxes = static_cast<int32_t>(r.occupied.size());
  out.messages.push_back(encode_message(r));
  return out;
}

EncodedReplies region(const octomap::OcTree& t, const octomap_rt::box_query_t& q, const QueryHeader& h,
                      const MapStamp& s, const std::string& id, const QueryBounds& bounds, query::WorkBudget& budget) {
  query::RegionOptions opt;
  opt.depth = q.depth;
  opt.include_free = q.include_free != 0;
  opt.max_voxels = std::max<size_t>(1, bounds.max_reply_bytes / kRegionVoxelBytes);
  const auto voxels = query::extract_region(t, query::key_box(t, &q.boxes[0], &q.boxes[3]), opt, &budget);
  if (budget.cut != query::Cut::kNone) return refused_by_budget(QueryMessage(q), budget, bounds, s, id);
  EncodedReplies out = replies_on(h.reply_channel);
  const int chunks = std::max<int>(1, static_cast<int>((voxels.size() + kRegionChunk - 1) / kRegionChunk));
  for (int c = 0; c < chunks; ++c) {
    octomap_rt::region_chunk_t m;
    stamp_reply(m, h, s, id, Reply::REPLY_OK, "");
    m.resolution = t.getResolution();
    m.chunk_index = c, m.num_chunks = chunks;
    m.total_voxels = static_cast<int64_t>(voxels.size());
    for (size_t i = size_t(c) * kRegionChunk; i < std::min(voxels.size(), size_t(c + 1) * kRegionChunk); ++i) {
      m.state.push_back(static_cast<int8_t>(voxels[i].state));
      m.depth.push_back(static_cast<int8_t>(voxels[i].depth));
      m.center_xyz.insert(m.center_xyz.end(), {voxels[i].center.x(), voxels[i].center.y(), voxels[i].center.z()});
    }
    m.num_voxels = static_cast<int32_t>(m.state.size());
    m.num_xyz = static_cast<int32_t>(m.center_xyz.size());
    out.messages.push_back(encode_message(m));
  }
  return out;
}

EncodedReplies grid(const octomap::OcTree& t, const octomap_rt::grid_query_t& q, const QueryHeader& h,
                    const MapStamp& s, const std::string& id, const QueryBounds& bounds, query::WorkBudget& budget) {
  query::GridRequest req;
  req.z_min = q.z_min, req.z_max = q.z_max;
  req.cell_voxels = q.cell_size > 0 ? static_cast<int>(std::lround(q.cell_size / t.getResolution())) : 1;
  req.window = q.use_window != 0;
  req.x_min = q.window_min[0], req.y_min = q.window_min[1], req.x_max = q.window_max[0], req.y_max = q.window_max[1];
  req.max_cells = std::min<int64_t>(kMaxGridCells, static_cast<int64_t>(bounds.max_reply_bytes));
  const query::Grid2D g = query::projected_grid(t, req, &budget);
  if (budget.cut != query::Cut::kNone) return refused_by_budget(QueryMessage(q), budget, bounds, s, id);
  EncodedReplies out = replies_on(h.reply_channel);
  const int rows_per = std::max(1, kGridChunkCells / std::max(1, g.width));
  const int chunks = std::max(1, (g.height + rows_per - 1) / rows_per);
  for (int c = 0; c < chunks; ++c) {
    octomap_rt::grid_t m;
    stamp_reply(m, h, s, id, Reply::REPLY_OK, "");
    m.cell_size = g.cell_size, m.origin_x = g.origin_x, m.origin_y = g.origin_y;
    m.z_min = q.z_min, m.z_max = q.z_max;
    m.width = g.width, m.height = g.height;
    m.chunk_index = c, m.num_chunks = chunks;
    m.row_start = c * rows_per;
    m.num_rows = std::max(0, std::min(rows_per, g.height - m.row_start));
    const size_t first = size_t(m.row_start) * g.width, n = size_t(m.num_rows) * g.width;
    for (size_t i = first; i < first + n; ++i) m.cells.push_back(static_cast<int8_t>(g.cells[i]));
    m.num_cells = static_cast<int32_t>(n);
    out.messages.push_back(encode_message(m));
  }
  return out;
}

}  // namespace

QueryHeader header_of(const QueryMessage& q) {
  return std::visit(
      [](const auto& m) {
        QueryHeader h;
        h.request_id = m.request_id, h.min_snapshot_id = m.min_snapshot_id, h.wait_seq = m.wait_seq;
        h.wait_timeout_ms = m.wait_timeout_ms;
        h.client_id = m.client_id, h.reply_channel = m.reply_channel, h.wait_robot_id = m.wait_robot_id;
        return h;
      },
      q);
}

std::string validate_query(const QueryMessage& q, double resolution) {
  return std::visit([&](const auto& m) { return validate(m, resolution); }, q);
}

EncodedReplies answer_query(const octomap::OcTree& t, const QueryMessage& q, const MapStamp& s, const std::string& id,
                            const QueryBounds& bounds, query::WorkBudget& budget, const protocol::ShardSet& shard) {
  const QueryHeader h = header_of(q);
  // Points are bounded by the message (at most 64 KiB of them, one search each).
  if (auto* p = std::get_if<octomap_rt::occupancy_query_t>(&q)) return points(t, *p, h, s, id);
  if (auto* p = std::get_if<octomap_rt::ray_query_t>(&q)) return rays(t, *p, h, s, id, bounds, budget, shard);
  if (auto* p = std::get_if<octomap_rt::box_query_t>(&q))
    return p->mode == Box::MODE_REGION ? region(t, *p, h, s, id, bounds, budget)
                                       : box_counts(t, *p, h, s, id, bounds, budget);
  if (std::holds_alternative<octomap_rt::distance_query_t>(q))
    throw std::logic_error("distance queries are answered by read_distance (daemon/queries/distance_answers.h)");
  return grid(t, std::get<octomap_rt::grid_query_t>(q), h, s, id, bounds, budget);
}

std::string cut_reason(const query::WorkBudget& b, const QueryBounds& bounds) {
  switch (b.cut) {
    case query::Cut::kWork:
      return "the work bound of " + std::to_string(bounds.max_work) + " node visits or ray steps (--query-max-work)";
    case query::Cut::kTime:
      return "the time bound under the map lock of " + std::to_string(bounds.lock_ms) + " ms (--query-lock-ms)";
    case query::Cut::kStopping: return "the server is stopping";
    case query::Cut::kNone: break;
  }
  return "not cut";
}

EncodedReplies error_reply(const QueryMessage& q, int8_t status, const std::string& error, const MapStamp& s,
                           const std::string& id) {
  const QueryHeader h = header_of(q);
  EncodedReplies out = replies_on(h.reply_channel);
  auto one = [&](auto m) {
    stamp_reply(m, h, s, id, status, error);
    out.messages.push_back(encode_message(m));
  };
  if (std::holds_alternative<octomap_rt::occupancy_query_t>(q))
    one(octomap_rt::occupancy_reply_t{});
  else if (std::holds_alternative<octomap_rt::ray_query_t>(q))
    one(octomap_rt::ray_reply_t{});
  else if (std::holds_alternative<octomap_rt::grid_query_t>(q))
    one(octomap_rt::grid_t{});
  else if (auto* d = std::get_if<octomap_rt::distance_query_t>(&q))
    out.messages.push_back(distance_error_message(*d, status, error, s, id));
  else if (std::get<octomap_rt::box_query_t>(q).mode == Box::MODE_REGION)
    one(octomap_rt::region_chunk_t{});
  else
    one(octomap_rt::box_reply_t{});
  return out;
}

}  // namespace ort::daemon
