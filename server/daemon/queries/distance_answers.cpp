#include "daemon/queries/distance_answers.h"

#include <cmath>
#include <cstring>
#include <memory>
#include <string_view>

#include "octomap_rt/distance_box_chunk_t.hpp"
#include "octomap_rt/distance_path_reply_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "protocol/limits.h"
#include "protocol/map_protocol.h"
#include "protocol/zstd_codec.h"

namespace ort::daemon {
namespace {

using Query = octomap_rt::distance_query_t;
using Reply = octomap_rt::occupancy_reply_t;

// The common stamp and the distance the reply's values are capped at.
template <class M>
void stamp(M& m, const Query& q, const MapStamp& s, const std::string& server_id, int8_t status,
           const std::string& error) {
  stamp_reply(m, q, s, server_id, status, error);
  m.max_distance = q.max_distance;
}

distance::DistanceOptions options_of(const Query& q, const DistanceServiceConfig& cfg) {
  distance::DistanceOptions o;
  o.max_distance = q.max_distance;
  o.cell_voxels = q.mode == Query::MODE_BOX ? q.cell_voxels : 1;
  o.unknown = q.unknown_as == Query::UNKNOWN_OCCUPIED ? distance::UnknownAs::kOccupied : distance::UnknownAs::kFree;
  if (cfg.shard.sharded()) {  // a shard's share: the obstacles of its own regions (PROTOCOL.md, "Shards")
    o.ownership.region_depth = cfg.shard.region_depth;
    o.ownership.owns = [set = cfg.shard](uint32_t x, uint32_t y, uint32_t z) {
      return protocol::shard_of(set, protocol::RegionCoords{x, y, z}) == set.index;
    };
  }
  return o;
}

// The points' field: from the cache when the read took its box (read_points' cover), else computed.
std::vector<distance::PointDistance> answer_points(distance::PointsRead& read, const distance::SquaredEdt& edt,
                                                   distance::FieldCache* cache) {
  if (!cache || read.grids.size() != 1 || !cache->holds(read.grids[0].box, read.opt))
    return distance::answer_points(read, edt);
  const distance::DistanceField* f = &cache->update(std::move(read.grids[0]), edt, read.resolution, read.opt);
  return distance::answer_points(read, std::span<const distance::DistanceField* const>(&f, 1));
}

void points_reply(EncodedReplies& out, const Query& q, const MapStamp& s, const std::string& id,
                  distance::PointsRead& read, const distance::SquaredEdt& edt, distance::FieldCache* cache) {
  const auto d = answer_points(read, edt, cache);
  octomap_rt::distance_points_reply_t r{};
  stamp(r, q, s, id, Reply::REPLY_OK, "");
  r.cell_size = read.resolution * read.opt.cell_voxels;
  for (const auto& p : d) {
    r.distance.push_back(p.distance);
    if (q.with_gradient) r.gradient.insert(r.gradient.end(), p.gradient.begin(), p.gradient.end());
  }
  r.num_points = static_cast<int32_t>(r.distance.size());
  r.num_gradient = static_cast<int32_t>(r.gradient.size());
  out.messages.push_back(encode_message(r));
}

void path_reply(EncodedReplies& out, const Query& q, const MapStamp& s, const std::string& id, distance::PathRead& read,
                const distance::SquaredEdt& edt, distance::FieldCache* cache) {
  const auto c = distance::path_clearance(read, answer_points(read.points, edt, cache));
  octomap_rt::distance_path_reply_t r{};
  stamp(r, q, s, id, Reply::REPLY_OK, "");
  r.min_distance = c.min_distance;
  std::copy(c.min_point.begin(), c.min_point.end(), r.min_xyz);
  r.min_arc_length = c.min_arc_length;
  r.min_sample = c.min_sample;
  r.num_samples = c.num_samples;
  out.messages.push_back(encode_message(r));
}

void box_reply(EncodedReplies& out, const Query& q, const MapStamp& s, const std::string& id, distance::BoxRead& read,
               const distance::SquaredEdt& edt, const DistanceServiceConfig& cfg, distance::FieldCache* cache) {
  // A box the cache can hold is transformed where its grid changed only (field_cache.h).
  const bool cached = cache && read.grid.box.dims.cells() <= cfg.limits.single_grid_cells;
  const auto b = cached
                     ? distance::answer_box(read, cache->update(std::move(read.grid), edt, read.resolution, read.opt),
                                            q.with_gradient != 0)
                     : distance::answer_box(read, edt, q.with_gradient != 0);
  // Little-endian hosts only (x86-64, arm64). Without the gradient the distances are the blob's
  // bytes as they are (no copy); an empty part is not copied: memcpy from an empty vector's null
  // data() is undefined even for 0 bytes.
  std::string joined;
  if (!b.gradient.empty()) {
    joined.resize(b.squared.size() * 4 + b.gradient.size() * 4);
    if (!b.squared.empty()) std::memcpy(joined.data(), b.squared.data(), b.squared.size() * 4);
    std::memcpy(joined.data() + b.squared.size() * 4, b.gradient.data(), b.gradient.size() * 4);
  }
  const std::string_view raw =
      b.gradient.empty() ? std::string_view(reinterpret_cast<const char*>(b.squared.data()), b.squared.size() * 4)
                         : std::string_view(joined);
  const std::string blob = cfg.zstd_level != 0 ? protocol::zstd_compress(raw, cfg.zstd_level) : std::string(raw);
  if (int64_t(blob.size()) > cfg.max_reply_bytes) {
    const std::string why = "the box's field is " + std::to_string(blob.size()) + " bytes compressed (at most " +
                            std::to_string(cfg.max_reply_bytes) +
                            "): ask for a smaller box, a coarser cell or no gradient";
    out.messages.push_back(distance_error_message(q, Reply::REPLY_BAD_REQUEST, why, s, id));
    out.refused = why;
    return;
  }
  const size_t chunk = protocol::kChunkDataBytes;
  const int32_t chunks = static_cast<int32_t>(std::max<size_t>(1, (blob.size() + chunk - 1) / chunk));
  const int64_t hash = protocol::blob_hash(blob.data(), blob.size());
  for (int32_t c = 0; c < chunks; ++c) {
    octomap_rt::distance_box_chunk_t m{};
    stamp(m, q, s, id, Reply::REPLY_OK, "");
    m.cell_size = b.cell_size;
    for (int a = 0; a < 3; ++a) m.origin[a] = b.origin[a];
    m.size[0] = b.cells.dims.nx, m.size[1] = b.cells.dims.ny, m.size[2] = b.cells.dims.nz;
    m.with_gradient = q.with_gradient ? 1 : 0;
    m.compression = cfg.zstd_level != 0 ? m.COMPRESSION_ZSTD : m.COMPRESSION_NONE;
    m.uncompressed_size = static_cast<int64_t>(raw.size());
    m.total_size = static_cast<int64_t>(blob.size());
    m.blob_hash = hash;
    m.num_chunks = chunks, m.chunk_index = c;
    const size_t first = size_t(c) * chunk, n = std::min(chunk, blob.size() - std::min(blob.size(), first));
    m.data.assign(blob.begin() + std::ptrdiff_t(first), blob.begin() + std::ptrdiff_t(first + n));
    m.num_bytes = static_cast<int32_t>(n);
    out.messages.push_back(encode_message(m));
  }
}

// The deferred part, with anything it throws turned into a BAD_REQUEST reply saying why.
template <class Body>
std::function<void(EncodedReplies&)> guarded(std::shared_ptr<const Query> q, const MapStamp& s, const std::string& id,
                                             Body body) {
  return [q, s, id, body](EncodedReplies& r) {
    try {
      body(r);
    } catch (const std::exception& e) {
      r.messages = {distance_error_message(*q, Reply::REPLY_BAD_REQUEST, e.what(), s, id)};
      r.refused = e.what();
    }
  };
}

}  // namespace

std::string validate_distance(const Query& q, double resolution, const DistanceServiceConfig& cfg) {
  if (q.mode != Query::MODE_POINTS && q.mode != Query::MODE_BOX && q.mode != Query::MODE_PATH)
    return "unknown mode " + std::to_string(q.mode);
  if (q.unknown_as != Query::UNKNOWN_FREE && q.unknown_as != Query::UNKNOWN_OCCUPIED)
    return "unknown_as " + std::to_string(q.unknown_as) + " is not 0 (free) or 1 (occupied)";
  if (q.mode == Query::MODE_BOX && (q.cell_voxels < 1 || q.cell_voxels > distance::kMaxCellVoxels))
    return "cell_voxels " + std::to_string(q.cell_voxels) + " is not in 1.." + std::to_string(distance::kMaxCellVoxels);
  if (std::string bad = distance::check_options(options_of(q, cfg), resolution, cfg.limits); !bad.empty()) return bad;
  if (q.num_xyz % 3) return "num_xyz is not a multiple of 3";
  for (float v : q.xyz)
    if (!std::isfinite(v)) return "a point is not finite";
  if (q.mode == Query::MODE_PATH && q.num_xyz < 3) return "a path needs at least one vertex";
  if (q.mode == Query::MODE_BOX)
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(q.box_min[a]) || !std::isfinite(q.box_max[a]) || q.box_min[a] > q.box_max[a])
        return "box corners must be finite with min <= max";
  return "";
}

EncodedReplies read_distance(const octomap::OcTree& tree, const Query& q, const MapStamp& s,
                             const std::string& server_id, const DistanceServiceConfig& cfg,
                             const distance::SquaredEdt& edt, distance::FieldCache* cache) {
  EncodedReplies out;
  out.channel = q.reply_channel;
  out.client_id = q.client_id;
  const distance::DistanceOptions opt = options_of(q, cfg);
  auto query = std::make_shared<const Query>(q);
  // Points and paths read the cached field's box where it holds theirs (their answer is the same).
  std::function<std::optional<distance::CellBox>(const distance::CellBox&)> cover;
  if (cache) cover = [cache, &opt](const distance::CellBox& want) { return cache->covering(want, opt); };
  if (q.mode == Query::MODE_POINTS) {
    auto read = std::make_shared<distance::PointsRead>(distance::read_points(tree, q.xyz, opt, cfg.limits, cover));
    out.finish = guarded(query, s, server_id,
                         [=](EncodedReplies& r) { points_reply(r, *query, s, server_id, *read, edt, cache); });
  } else if (q.mode == Query::MODE_PATH) {
    const std::vector<double> v(q.xyz.begin(), q.xyz.end());
    auto read = std::make_shared<distance::PathRead>(distance::read_path(tree, v, opt, cfg.limits, cover));
    out.finish = guarded(query, s, server_id,
                         [=](EncodedReplies& r) { path_reply(r, *query, s, server_id, *read, edt, cache); });
  } else {
    auto read = std::make_shared<distance::BoxRead>(distance::read_box(tree, q.box_min, q.box_max, opt, cfg.limits));
    out.finish = guarded(query, s, server_id,
                         [=, &cfg](EncodedReplies& r) { box_reply(r, *query, s, server_id, *read, edt, cfg, cache); });
  }
  return out;
}

std::vector<uint8_t> distance_error_message(const Query& q, int8_t status, const std::string& error, const MapStamp& s,
                                            const std::string& server_id) {
  if (q.mode == Query::MODE_BOX) {
    octomap_rt::distance_box_chunk_t m{};
    stamp(m, q, s, server_id, status, error);
    return encode_message(m);
  }
  if (q.mode == Query::MODE_PATH) {
    octomap_rt::distance_path_reply_t m{};
    stamp(m, q, s, server_id, status, error);
    return encode_message(m);
  }
  octomap_rt::distance_points_reply_t m{};
  stamp(m, q, s, server_id, status, error);
  return encode_message(m);
}

}  // namespace ort::daemon
