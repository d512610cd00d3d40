#include "map_client/map_mirror.h"

#include <algorithm>
#include <chrono>

#include "core/clock.h"
#include "protocol/delta_codec.h"

namespace ort::client {
namespace {
using Delta = octomap_rt::map_delta_t;
}

MapMirror::MapMirror(MapClient& client, MirrorOptions opts) : client_(client), opts_(std::move(opts)) {
  client_.on_delta([this](const Delta& d) { on_delta(d); });
  client_.on_info([this](const octomap_rt::map_info_t& info) { on_info(info); });
}

void MapMirror::on_delta(const Delta& d) {
  highest_seq_ = std::max(highest_seq_, d.delta_seq);
  if (syncing_ || !tree_) {
    buffered_.push_back(d);
    return;
  }
  process(d, /*buffered=*/false);
}

// The server publishes a delta before any map_info_t naming its delta_seq, from one socket,
// so they arrive in that order: an info naming a delta_seq never received means that delta
// was lost. Without this a lost last delta (the end of a stream) would go unseen for good.
void MapMirror::on_info(const octomap_rt::map_info_t& info) {
  if (opts_.on_info) opts_.on_info(info);
  const bool baseline = !info_seen_;  // synced before any info: its deltas' seqs were unknown
  info_seen_ = true;
  latest_info_seq_ = info.delta_seq;
  if (info.delta_seq < highest_seq_ || baseline) highest_seq_ = info.delta_seq;  // or the server started again
  if (syncing_ || !tree_ || need_sync_) return;
  if (info.map_epoch != epoch_) {  // the map's history forked since the snapshot
    stats_.epoch_changes++;
    gap();
    return;
  }
  if (info.delta_seq <= highest_seq_) return;
  highest_seq_ = info.delta_seq;  // counted once
  gap();
}

void MapMirror::sync() {
  // Deltas sent before the latest info are in the fresh snapshot asked for now.
  if (!info_seen_) client_.wait_info(1.5);  // 1 Hz; a server without map info: no check
  const int64_t sent_before = latest_info_seq_;
  syncing_ = true;
  buffered_.clear();
  FetchedSnapshot s;
  try {
    s = client_.fetch_snapshot(opts_.snapshot_format, opts_.fetch_timeout_s);
  } catch (...) {
    syncing_ = false;
    throw;
  }
  tree_ = s.tree();
  highest_seq_ = std::max(highest_seq_, sent_before);
  version_ = s.snapshot_id;
  epoch_ = s.map_epoch;
  started_ = false;
  set_open_ = false;
  last_seq_ = -1;
  need_sync_ = false;
  syncing_ = false;
  stats_.snapshots++;
  std::vector<Delta> pending;
  pending.swap(buffered_);
  std::sort(pending.begin(), pending.end(), [](const Delta& a, const Delta& b) { return a.delta_seq < b.delta_seq; });
  for (const Delta& d : pending) {
    if (need_sync_) break;
    process(d, /*buffered=*/true);
  }
}

void MapMirror::spin(double seconds) {
  const auto t0 = SteadyClock::now();
  auto left = [&] { return seconds - seconds_since(t0); };
  while (left() > 0) {
    if (need_sync_ || !tree_) sync();
    client_.spin(std::min(0.05, std::max(0.0, left())));
  }
}

void MapMirror::gap() {
  stats_.gaps++;
  if (opts_.resync) need_sync_ = true;
}

void MapMirror::process(const Delta& d, bool buffered) {
  if (need_sync_) return;
  if (d.map_epoch != epoch_) {
    if (buffered) {  // sent before the snapshot's history began: not part of it
      stats_.deltas_skipped++;
      return;
    }
    stats_.epoch_changes++;
    gap();
    return;
  }
  if (!started_) {
    if (d.to_version <= version_) {  // already in the snapshot
      stats_.deltas_skipped++;
      last_seq_ = d.delta_seq;
      return;
    }
    const bool continues = last_seq_ >= 0 && d.delta_seq == last_seq_ + 1;
    if (d.from_version > version_ || (d.part_index != 0 && !continues)) {
      gap();  // changes between the snapshot and this delta were not seen
      if (!opts_.resync) apply(d);
      return;
    }
    started_ = true;
  } else if (d.delta_seq != last_seq_ + 1) {
    // A server restarted from its clean save numbers its deltas from 0 again; a set that starts
    // at the mirror's complete version continues the chain whatever its delta_seq.
    const bool chains = !set_open_ && d.part_index == 0 && d.from_version == version_;
    if (!chains) {
      gap();
      if (opts_.resync) return;
    }
  }
  apply(d);
}

void MapMirror::apply(const Delta& d) {
  std::vector<protocol::VoxelChange> changes;
  try {
    changes = protocol::decode_delta_part({reinterpret_cast<const char*>(d.data.data()), d.data.size()}, d.num_voxels,
                                          d.uncompressed_size, d.mode);
  } catch (const std::exception&) {
    stats_.bad_deltas++;
    last_seq_ = d.delta_seq;
    gap();  // its changes are lost: as if it never came
    return;
  }
  const float occ = tree_->getClampingThresMaxLog(), free = tree_->getClampingThresMinLog();
  for (const protocol::VoxelChange& c : changes) {
    const float value =
        d.mode == Delta::MODE_LOG_ODDS ? c.value : (static_cast<int8_t>(c.value) == Delta::CLASS_OCCUPIED ? occ : free);
    tree_->setNodeValue(protocol::unpack_key(c.key), value);
  }
  last_seq_ = d.delta_seq;
  const bool complete = d.part_index == d.num_parts - 1;
  if (complete) version_ = std::max(version_, d.to_version);
  set_open_ = !complete;
  stats_.deltas_applied++;
  stats_.voxels_applied += static_cast<int64_t>(changes.size());
  const int64_t bytes = d.getEncodedSize();
  stats_.delta_bytes += bytes;
  if (opts_.on_delta)
    opts_.on_delta(AppliedDelta{d.delta_seq, d.to_version, static_cast<int32_t>(changes.size()), complete, bytes});
}

}  // namespace ort::client
