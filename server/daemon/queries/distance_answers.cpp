#include "daemon/queries/distance_answers.h"

#include <cmath>
#include <cstring>
#include <memory>
#include <string_view>

#include "daemon/queries/box_frames.h"
#include "daemon/queries/field_patch.h"
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

// How a read uses the field cache: not at all, with a grid read whole, or with a patch.
struct CacheUse {
  enum Kind { kNone, kWhole, kPatch } kind = kNone;
  distance::GridPatch patch;
  uint64_t version = 0;  // the map state read
};

// Under the lock: the patch that brings the cache's pending entry (when it is `box`) to `version`.
std::optional<distance::GridPatch> patch_for(const octomap::OcTree& tree, const distance::CellBox& box,
                                             const distance::DistanceOptions& opt, uint64_t version,
                                             distance::FieldCache& cache, ChangeJournal* journal) {
  if (!journal) return std::nullopt;
  journal->arm();
  const auto p = cache.pending(opt, tree.getResolution());
  if (!p || !distance::same_cells(p->box, box)) return std::nullopt;
  return patch_from_journal(*journal, tree, box, opt, p->version, version);
}

// The field of a grid read `use` says how to take: from the cache (updated), else computed.
const distance::DistanceField* cached_field(distance::OccupancyGrid& grid, const CacheUse& use, double resolution,
                                            const distance::DistanceOptions& opt, const distance::SquaredEdt& edt,
                                            distance::FieldCache* cache) {
  if (!cache || use.kind == CacheUse::kNone) return nullptr;
  if (use.kind == CacheUse::kPatch) return &cache->update(use.patch, edt, opt);
  return &cache->update(std::move(grid), edt, resolution, opt, use.version);
}

// The points' field: from the cache when the read took its box (read_points' cover), else computed.
std::vector<distance::PointDistance> answer_points(distance::PointsRead& read, const distance::SquaredEdt& edt,
                                                   distance::FieldCache* cache, const CacheUse& use) {
  const distance::DistanceField* f =
      read.grids.size() == 1 ? cached_field(read.grids[0], use, read.resolution, read.opt, edt, cache) : nullptr;
  if (!f) return distance::answer_points(read, edt);
  return distance::answer_points(read, std::span<const distance::DistanceField* const>(&f, 1));
}

void points_reply(EncodedReplies& out, const Query& q, const MapStamp& s, const std::string& id,
                  distance::PointsRead& read, const distance::SquaredEdt& edt, distance::FieldCache* cache,
                  const CacheUse& use) {
  const auto d = answer_points(read, edt, cache, use);
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
                const distance::SquaredEdt& edt, distance::FieldCache* cache, const CacheUse& use) {
  const auto c = distance::path_clearance(read, answer_points(read.points, edt, cache, use));
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
               const distance::SquaredEdt& edt, const DistanceServiceConfig& cfg, distance::FieldCache* cache,
               const CacheUse& use) {
  // A box the cache holds is transformed where its grid changed only (field_cache.h), and
  // asked again over a field that did not change, it is sent the same bytes (kept, not made again).
  const distance::DistanceField* f = cached_field(read.grid, use, read.resolution, read.opt, edt, cache);
  const bool gradient = q.with_gradient != 0;
  std::string key;
  if (f) {
    key = std::to_string(read.cells.key_lo[0]) + "," + std::to_string(read.cells.key_lo[1]) + "," +
          std::to_string(read.cells.key_lo[2]) + "/" + std::to_string(read.cells.dims.nx) + "x" +
          std::to_string(read.cells.dims.ny) + "x" + std::to_string(read.cells.dims.nz) + "/" +
          std::to_string(read.pad) + (gradient ? "g" : "") + "/z" + std::to_string(cfg.zstd_level) + "/" +
          std::to_string(read.opt.max_distance);
  }
  BoxBlob made;
  const distance::FieldCache::Memo* kept = f ? cache->memo(key) : nullptr;
  if (!kept) {
    // Made again: per z-slab, the slabs whose bytes did not change keep their frames (box_frames.h).
    if (f) {
      made =
          box_blob(read, *f, gradient, cfg.zstd_level, cfg.threads, key, &cache->kept_frames(), cfg.reply_slab_cells);
      cache->count_frames(made.frames, made.frames_kept);
      kept = &cache->keep_memo(distance::FieldCache::Memo{key, std::move(made.bytes), made.raw_size});
    } else {
      const auto whole = distance::compute_field(read.grid, edt, read.resolution, read.opt);
      made = box_blob(read, whole, gradient, cfg.zstd_level, cfg.threads, key, nullptr, cfg.reply_slab_cells);
    }
  }
  const std::string& blob = kept ? kept->bytes : made.bytes;
  const int64_t raw_size = kept ? kept->raw_size : made.raw_size;
  if (int64_t(blob.size()) > cfg.max_reply_bytes) {
    const std::string why = "the box's field is " + std::to_string(blob.size()) + " bytes compressed (at most " +
                            std::to_string(cfg.max_reply_bytes) +
                            "): ask for a smaller box, a coarser cell or no gradient";
    out.messages.push_back(distance_error_message(q, Reply::REPLY_BAD_REQUEST, why, s, id));
    out.refused = why;
    return;
  }
  const double cell_size = read.resolution * read.opt.cell_voxels;
  const std::array<double, 3> origin = distance::box_origin(read);
  const size_t chunk = protocol::kChunkDataBytes;
  const int32_t chunks = static_cast<int32_t>(std::max<size_t>(1, (blob.size() + chunk - 1) / chunk));
  const int64_t hash = protocol::blob_hash(blob.data(), blob.size());
  for (int32_t c = 0; c < chunks; ++c) {
    octomap_rt::distance_box_chunk_t m{};
    stamp(m, q, s, id, Reply::REPLY_OK, "");
    m.cell_size = cell_size;
    for (int a = 0; a < 3; ++a) m.origin[a] = origin[a];
    m.size[0] = read.cells.dims.nx, m.size[1] = read.cells.dims.ny, m.size[2] = read.cells.dims.nz;
    m.with_gradient = q.with_gradient ? 1 : 0;
    m.compression = cfg.zstd_level != 0 ? m.COMPRESSION_ZSTD : m.COMPRESSION_NONE;
    m.uncompressed_size = raw_size;
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
                             const distance::SquaredEdt& edt, distance::FieldCache* cache, ChangeJournal* journal) {
  EncodedReplies out;
  out.channel = q.reply_channel;
  out.client_id = q.client_id;
  const distance::DistanceOptions opt = options_of(q, cfg);
  const double res = tree.getResolution();
  const auto version = static_cast<uint64_t>(s.snapshot_id);
  auto query = std::make_shared<const Query>(q);
  auto use = std::make_shared<CacheUse>();
  use->version = version;
  // Points and paths read the cached field's box where it holds theirs (their answer is the
  // same): brought up to date from the change lists where the journal can, else read again.
  distance::CoverFn cover;
  if (cache)
    cover = [&, cache, use](const distance::CellBox& want) -> std::optional<distance::GridCover> {
      const auto box = cache->covering(want, opt, res, journal != nullptr);
      if (!box || box->dims.cells() > cfg.limits.max_grid_cells) return std::nullopt;
      if (auto patch = patch_for(tree, *box, opt, version, *cache, journal)) {
        use->kind = CacheUse::kPatch, use->patch = std::move(*patch);
        cache->will_advance(version);
        return distance::GridCover{*box, false};
      }
      if (!cache->covering(want, opt, res, false)) return std::nullopt;
      use->kind = CacheUse::kWhole;
      cache->will_hold(*box, opt, res, version);
      return distance::GridCover{*box, true};
    };
  if (q.mode == Query::MODE_POINTS) {
    auto read = std::make_shared<distance::PointsRead>(distance::read_points(tree, q.xyz, opt, cfg.limits, cover));
    out.finish = guarded(query, s, server_id,
                         [=](EncodedReplies& r) { points_reply(r, *query, s, server_id, *read, edt, cache, *use); });
  } else if (q.mode == Query::MODE_PATH) {
    const std::vector<double> v(q.xyz.begin(), q.xyz.end());
    auto read = std::make_shared<distance::PathRead>(distance::read_path(tree, v, opt, cfg.limits, cover));
    out.finish = guarded(query, s, server_id,
                         [=](EncodedReplies& r) { path_reply(r, *query, s, server_id, *read, edt, cache, *use); });
  } else {
    auto read = std::make_shared<distance::BoxRead>(distance::plan_box(tree, q.box_min, q.box_max, opt, cfg.limits));
    // A box the cache can hold: from the change lists when it is the cached box, else read whole.
    const bool cacheable = cache && read->grid.box.dims.cells() <= cfg.limits.single_grid_cells;
    if (auto patch = cacheable ? patch_for(tree, read->grid.box, opt, version, *cache, journal) : std::nullopt) {
      use->kind = CacheUse::kPatch, use->patch = std::move(*patch);
      cache->will_advance(version);
    } else {
      read->grid = distance::read_occupancy(tree, read->grid.box, opt.unknown, opt.ownership);
      if (cacheable) use->kind = CacheUse::kWhole, cache->will_hold(read->grid.box, opt, res, version);
    }
    out.finish = guarded(query, s, server_id, [=, &cfg](EncodedReplies& r) {
      box_reply(r, *query, s, server_id, *read, edt, cfg, cache, *use);
    });
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
