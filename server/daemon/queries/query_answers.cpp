#include "daemon/queries/query_answers.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "octomap_rt/region_chunk_t.hpp"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
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

int64_t now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

template <class M>
std::vector<uint8_t> encode(const M& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

template <class M>
void stamp_reply(M& m, const QueryHeader& h, const MapStamp& s, const std::string& server_id, int8_t status,
                 const std::string& error) {
  m.utime = now_us();
  m.request_id = h.request_id;
  m.snapshot_id = s.snapshot_id;
  m.map_utime = s.map_utime;
  m.status = status;
  m.server_id = server_id;
  m.client_id = h.client_id;
  m.error = error;
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
  return {h.reply_channel, {encode(r)}};
}

EncodedReplies rays(const octomap::OcTree& t, const octomap_rt::ray_query_t& q, const QueryHeader& h, const MapStamp& s,
                    const std::string& id) {
  query::RayBatchOptions opt;
  opt.ignore_unknown = q.ignore_unknown != 0;
  opt.max_range = q.max_range;
  const auto answers = query::cast_rays(t, q.origin_xyz, q.direction_xyz, opt);
  octomap_rt::ray_reply_t r;
  stamp_reply(r, h, s, id, Reply::REPLY_OK, "");
  r.num_rays = static_cast<int32_t>(answers.size());
  for (const query::RayAnswer& a : answers) {
    r.hit.push_back(a.hit);
    r.end_state.push_back(static_cast<int8_t>(a.end_state));
    r.end_xyz.insert(r.end_xyz.end(), {a.end.x(), a.end.y(), a.end.z()});
  }
  r.num_xyz = static_cast<int32_t>(r.end_xyz.size());
  return {h.reply_channel, {encode(r)}};
}

EncodedReplies box_counts(const octomap::OcTree& t, const octomap_rt::box_query_t& q, const QueryHeader& h,
                          const MapStamp& s, const std::string& id) {
  octomap_rt::box_reply_t r;
  stamp_reply(r, h, s, id, Reply::REPLY_OK, "");
  for (size_t i = 0; i + 5 < q.boxes.size(); i += 6) {
    const query::KeyBox b = query::key_box(t, &q.boxes[i], &q.boxes[i + 3]);
    if (q.mode == Box::MODE_ANY_OCCUPIED) {
      r.occupied.push_back(-1), r.free.push_back(-1), r.unknown.push_back(-1);
      r.any_occupied.push_back(query::any_occupied(t, b));
    } else {
      const query::BoxCounts c = query::count_box(t, b);
      r.occupied.push_back(c.occupied), r.free.push_back(c.free), r.unknown.push_back(c.unknown);
      r.any_occupied.push_back(c.any_occupied());
    }
  }
  r.num_boxes = static_cast<int32_t>(r.occupied.size());
  return {h.reply_channel, {encode(r)}};
}

EncodedReplies region(const octomap::OcTree& t, const octomap_rt::box_query_t& q, const QueryHeader& h,
                      const MapStamp& s, const std::string& id) {
  query::RegionOptions opt;
  opt.depth = q.depth;
  opt.include_free = q.include_free != 0;
  const auto voxels = query::extract_region(t, query::key_box(t, &q.boxes[0], &q.boxes[3]), opt);
  EncodedReplies out{h.reply_channel, {}};
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
    out.messages.push_back(encode(m));
  }
  return out;
}

EncodedReplies grid(const octomap::OcTree& t, const octomap_rt::grid_query_t& q, const QueryHeader& h,
                    const MapStamp& s, const std::string& id) {
  query::GridRequest req;
  req.z_min = q.z_min, req.z_max = q.z_max;
  req.cell_voxels = q.cell_size > 0 ? static_cast<int>(std::lround(q.cell_size / t.getResolution())) : 1;
  req.window = q.use_window != 0;
  req.x_min = q.window_min[0], req.y_min = q.window_min[1], req.x_max = q.window_max[0], req.y_max = q.window_max[1];
  req.max_cells = 4'000'000;
  const query::Grid2D g = query::projected_grid(t, req);
  EncodedReplies out{h.reply_channel, {}};
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
    out.messages.push_back(encode(m));
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

EncodedReplies answer_query(const octomap::OcTree& t, const QueryMessage& q, const MapStamp& s, const std::string& id) {
  const QueryHeader h = header_of(q);
  if (auto* p = std::get_if<octomap_rt::occupancy_query_t>(&q)) return points(t, *p, h, s, id);
  if (auto* p = std::get_if<octomap_rt::ray_query_t>(&q)) return rays(t, *p, h, s, id);
  if (auto* p = std::get_if<octomap_rt::box_query_t>(&q))
    return p->mode == Box::MODE_REGION ? region(t, *p, h, s, id) : box_counts(t, *p, h, s, id);
  return grid(t, std::get<octomap_rt::grid_query_t>(q), h, s, id);
}

EncodedReplies error_reply(const QueryMessage& q, int8_t status, const std::string& error, const MapStamp& s,
                           const std::string& id) {
  const QueryHeader h = header_of(q);
  EncodedReplies out{h.reply_channel, {}};
  auto one = [&](auto m) {
    stamp_reply(m, h, s, id, status, error);
    out.messages.push_back(encode(m));
  };
  if (std::holds_alternative<octomap_rt::occupancy_query_t>(q))
    one(octomap_rt::occupancy_reply_t{});
  else if (std::holds_alternative<octomap_rt::ray_query_t>(q))
    one(octomap_rt::ray_reply_t{});
  else if (std::holds_alternative<octomap_rt::grid_query_t>(q))
    one(octomap_rt::grid_t{});
  else if (std::get<octomap_rt::box_query_t>(q).mode == Box::MODE_REGION)
    one(octomap_rt::region_chunk_t{});
  else
    one(octomap_rt::box_reply_t{});
  return out;
}

}  // namespace ort::daemon
