#include "reply_timing.h"

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "core/clock.h"
#include "daemon/queries/box_frames.h"
#include "daemon/queries/distance_answers.h"
#include "distance/squared_edt.h"
#include "octomap_rt/distance_box_chunk_t.hpp"
#include "protocol/zstd_codec.h"

namespace ort::bench {
namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

ReplyTimes time_box_reply(const octomap::OcTree& tree, const double lo[3], const double hi[3],
                          const distance::DistanceOptions& opt, int threads, int zstd_level, int reps) {
  octomap_rt::distance_query_t q{};
  q.mode = q.MODE_BOX, q.max_distance = opt.max_distance, q.cell_voxels = opt.cell_voxels;
  q.unknown_as = opt.unknown == distance::UnknownAs::kOccupied ? q.UNKNOWN_OCCUPIED : q.UNKNOWN_FREE;
  std::copy(lo, lo + 3, q.box_min), std::copy(hi, hi + 3, q.box_max);
  q.client_id = "bench", q.reply_channel = "BENCH";
  daemon::DistanceServiceConfig cfg;
  cfg.zstd_level = zstd_level;
  cfg.limits.max_grid_cells = int64_t(1) << 40, cfg.limits.max_box_cells = int64_t(1) << 40;
  cfg.limits.single_grid_cells = int64_t(1) << 40;
  const distance::SquaredEdt edt = distance::cpu_edt(std::max(1, threads));
  distance::FieldCache cache;
  std::vector<double> read, whole, cached;
  ReplyTimes t;
  for (int r = 0; r <= std::max(1, reps); ++r) {  // run 0 untimed
    auto t0 = SteadyClock::now();
    daemon::EncodedReplies a = daemon::read_distance(tree, q, {}, "bench", cfg, edt, nullptr);
    const double read_ms = ms_since(t0);
    t0 = SteadyClock::now();
    a.finish(a);
    const double whole_ms = ms_since(t0);
    daemon::EncodedReplies b = daemon::read_distance(tree, q, {}, "bench", cfg, edt, &cache);
    t0 = SteadyClock::now();
    b.finish(b);
    const double cached_ms = ms_since(t0);
    if (r == 0) {
      t.chunks = int64_t(b.messages.size());
      octomap_rt::distance_box_chunk_t m;
      if (!b.messages.empty() && m.decode(b.messages[0].data(), 0, int(b.messages[0].size())) >= 0)
        t.blob_bytes = m.total_size, t.raw_bytes = m.uncompressed_size;
      continue;
    }
    read.push_back(read_ms), whole.push_back(whole_ms), cached.push_back(cached_ms);
  }
  t.read_ms = median(read), t.whole_ms = median(whole), t.cached_ms = median(cached);
  // Of the cached finish: the box cut out of the field with the clamp, and zstd of its bytes.
  distance::BoxRead br = distance::read_box(tree, lo, hi, opt, cfg.limits);
  const distance::DistanceField& f = cache.update(std::move(br.grid), edt, br.resolution, opt);
  std::vector<double> clamp, zstd;
  for (int r = 0; r < std::max(1, reps); ++r) {
    auto t0 = SteadyClock::now();
    const distance::BoxDistances b = distance::answer_box(br, f, false);
    clamp.push_back(ms_since(t0));
    t0 = SteadyClock::now();
    const std::string raw(reinterpret_cast<const char*>(b.squared.data()), b.squared.size() * 4);
    const std::string blob = zstd_level > 0 ? protocol::zstd_compress(raw, zstd_level) : raw;
    zstd.push_back(ms_since(t0));
  }
  t.clamp_ms = median(clamp), t.zstd_ms = median(zstd);
  std::vector<double> made, kept_ms;
  for (int r = 0; r < std::max(1, reps); ++r) {
    distance::KeptFrames kept;
    auto t0 = SteadyClock::now();
    const daemon::BoxBlob first = daemon::box_blob(br, f, false, zstd_level, threads, "box", &kept);
    made.push_back(ms_since(t0));
    t0 = SteadyClock::now();
    const daemon::BoxBlob again = daemon::box_blob(br, f, false, zstd_level, threads, "box", &kept);
    kept_ms.push_back(ms_since(t0));
    t.slab_frames = first.frames, t.slab_frames_kept = again.frames_kept;
    t.slab_blob_bytes = int64_t(first.bytes.size());
  }
  t.slabs_made_ms = median(made), t.slabs_kept_ms = median(kept_ms);
  // zstd's levels on the same bytes: what --distance-zstd-level trades.
  const distance::BoxDistances b = distance::answer_box(br, f, false);
  const std::string_view raw(reinterpret_cast<const char*>(b.squared.data()), b.squared.size() * 4);
  for (int level : {1, -1, -5, -20}) {
    std::vector<double> ms;
    size_t bytes = 0;
    for (int r = 0; r < std::max(1, reps); ++r) {
      const auto t0 = SteadyClock::now();
      bytes = protocol::zstd_compress(raw, level).size();
      ms.push_back(ms_since(t0));
    }
    t.levels += " " + std::to_string(level) + ": " + std::to_string(median(ms)).substr(0, 5) + " ms " +
                std::to_string(bytes) + " B;";
  }
  return t;
}

}  // namespace ort::bench
