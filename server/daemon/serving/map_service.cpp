#include "daemon/serving/map_service.h"
#include "core/clock.h"
#include "protocol/shards/shard_wire.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <shared_mutex>

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_info_t.hpp"
#include "protocol/ids.h"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
#include "protocol/map_protocol.h"
#include "protocol/version.h"

namespace ort::daemon {
namespace {

using protocol::chunks_to_send;
using protocol::next_fresh_due;
using protocol::next_servable;
using protocol::queued_of;
using protocol::QueuedMapRequest;
using protocol::RequestRefusal;
using protocol::SnapshotClock;

using Chunk = octomap_rt::map_chunk_t;

}  // namespace

MapService::MapService(LcmLoop& loop, MapState& map, MapServiceConfig cfg, std::function<int64_t()> last_delta_seq,
                       Log log)
    : loop_(loop),
      map_(map),
      cfg_(std::move(cfg)),
      last_delta_seq_(std::move(last_delta_seq)),
      log_(std::move(log)),
      store_(cfg_.snapshots) {}

MapService::~MapService() {
  try {
    stop();
  } catch (...) {}
}

void MapService::open() {
  if (sub_) return;
  // Requests are small: a modest LCM queue; our own bounded queue decides what is busy.
  sub_ = loop_.subscribe(
      cfg_.request_channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) { on_request(rb); }, 1024);
}

void MapService::start() {
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

void MapService::stop() {
  if (sub_) {
    loop_.unsubscribe(sub_);
    sub_ = 0;
  }
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

MapServiceStats MapService::stats() const {
  std::lock_guard lock(mutex_);
  MapServiceStats s = stats_;
  s.snapshots_taken = store_.taken();
  s.latest_snapshot_id = store_.latest_id();
  return s;
}

// On the LCM loop: check and queue, nothing slow.
void MapService::on_request(const lcm::ReceiveBuffer& rbuf) {
  octomap_rt::map_request_t req{};
  if (!protocol::check_request(rbuf.data, rbuf.data_size, req).ok()) {
    refuse(nullptr, protocol::RequestRefusal::kUndecodable, "");
    return;
  }
  RequestRefusal busy = RequestRefusal::kNone;
  size_t waiting = 0;
  {
    std::lock_guard lock(mutex_);
    waiting = queue_.size();
    if (queue_.size() >= cfg_.request_queue)
      busy = RequestRefusal::kBusy;
    else if (queued_of(queue_, req.client_id) >= cfg_.requests_per_client)
      busy = RequestRefusal::kClientBusy;
    if (busy == RequestRefusal::kNone) {
      queue_.push_back({std::move(req), SteadyClock::now()});
      cv_.notify_all();
      return;
    }
  }
  // The client's cue (client/map_client retries after it, with jitter): about the time the
  // requests ahead of it take, at least 100 ms.
  const int64_t retry_ms = std::max<int64_t>(100, static_cast<int64_t>(waiting) * 50);
  refuse(&req, busy, "retry after " + std::to_string(retry_ms) + " ms");
}

protocol::SnapshotClock MapService::snapshot_clock() {
  protocol::SnapshotClock c;
  c.now = SteadyClock::now();
  c.newest_taken = store_.taken_at();
  c.fresh_interval = std::chrono::duration_cast<SteadyClock::duration>(
      std::chrono::duration<double>(std::max(cfg_.fresh_interval_s, cfg_.snapshots.min_interval_s)));
  if (store_.latest_id() >= 0) {
    std::shared_lock lock(map_.mutex);
    const MapHoldNote note(map_.holders, "snapshot freshness check");
    c.newest_is_current = static_cast<int64_t>(map_.version) == store_.latest_id();
  }
  return c;
}

void MapService::run() {
  auto next_info = SteadyClock::now();
  std::unique_lock lock(mutex_);
  while (!stop_) {
    // The store is only touched on this thread: its clock may be read without the lock.
    lock.unlock();
    const SnapshotClock clock = snapshot_clock();
    lock.lock();
    const size_t pick = next_servable(queue_, clock);
    if (pick == SIZE_MAX) {
      const auto wake = std::min(next_info, next_fresh_due(queue_, clock));
      const size_t seen = queue_.size();
      cv_.wait_until(lock, wake, [&] { return stop_ || queue_.size() != seen; });
    }
    if (stop_) break;
    if (pick != SIZE_MAX) {
      const QueuedMapRequest queued = std::move(queue_[pick]);
      const octomap_rt::map_request_t& req = queued.req;
      queue_.erase(queue_.begin() + static_cast<std::ptrdiff_t>(pick));
      lock.unlock();
      try {
        serve(queued);
      } catch (const std::exception& e) {
        log_.error(text("map request ", req.request_id, " failed: ", e.what()));
      }
      lock.lock();
    }
    if (SteadyClock::now() >= next_info) {
      lock.unlock();
      publish_info();
      lock.lock();
      next_info = SteadyClock::now() +
                  std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(cfg_.info_period_s));
    }
  }
}

void MapService::serve(const protocol::QueuedMapRequest& queued) {
  const octomap_rt::map_request_t& req = queued.req;
  protocol::RequestRefusal why = protocol::check_map_request(req, cfg_.reply_prefix);
  if (why != protocol::RequestRefusal::kNone) return refuse(&req, why, "");
  bool took_new = false;
  // snapshot_id: < 0 a fresh snapshot, 0 the latest kept (maybe older than the map), > 0 that one.
  // A fresh request comes out of the queue only once the newest snapshot is fresh enough for
  // it (taken after it arrived: that one, no new copy) or a new one may be taken.
  std::shared_ptr<const SnapshotBlob> blob;
  if (req.snapshot_id < 0 && store_.latest_id() >= 0 && store_.taken_at() >= queued.arrived)
    blob = store_.newest(req.format);
  else if (req.snapshot_id <= 0)
    blob = store_.latest(map_, req.format, false, took_new);
  else
    blob = store_.find(static_cast<uint64_t>(req.snapshot_id), req.format);
  if (!blob)
    return refuse(&req, protocol::RequestRefusal::kUnknownSnapshot,
                  "snapshot " + std::to_string(req.snapshot_id) + " is not kept; the latest is " +
                      std::to_string(store_.latest_id()) + " (ask for 0 = latest)");
  const int32_t n = blob->num_chunks(protocol::kChunkDataBytes);
  for (int32_t i : req.chunk_indices)
    if (i >= n)
      return refuse(&req, protocol::RequestRefusal::kChunkOutOfRange,
                    "chunk " + std::to_string(i) + " of a snapshot of " + std::to_string(n) + " chunks");
  note_blob(*blob);
  if (took_new) publish_info();
  send_chunks(req, *blob);
  std::lock_guard lock(mutex_);
  stats_.requests_served++;
}

void MapService::note_blob(const SnapshotBlob& b) {
  std::lock_guard lock(mutex_);
  stats_.last_copy_lock_ms = b.contents.copy_lock_ms;
  stats_.max_copy_lock_ms = std::max(stats_.max_copy_lock_ms, b.contents.copy_lock_ms);
  stats_.last_serialize_ms = b.serialize_ms;
  stats_.last_compress_ms = b.compress_ms;
  stats_.last_raw_size = b.raw_size;
  stats_.last_size = static_cast<int64_t>(b.bytes.size());
}

void MapService::refuse(const octomap_rt::map_request_t* req, protocol::RequestRefusal why, const std::string& detail) {
  {
    std::lock_guard lock(mutex_);
    stats_.requests_rejected++;
    stats_.refusals[static_cast<size_t>(why)]++;
  }
  if (!req || !protocol::can_reply(*req, cfg_.reply_prefix)) return;  // nowhere safe to answer: ignored (counted)
  Chunk c{};
  c.utime = now_utime();
  c.request_id = req->request_id;
  c.snapshot_id = req->snapshot_id;
  c.format = req->format;
  c.server_id = cfg_.server_id;
  c.client_id = protocol::valid_name(req->client_id) ? req->client_id : "";
  c.error = std::string(to_string(why)) + (detail.empty() ? "" : ": " + detail);
  loop_.publish(req->reply_channel, c);
}

void MapService::send_chunks(const octomap_rt::map_request_t& req, const SnapshotBlob& blob) {
  const size_t chunk = protocol::kChunkDataBytes;
  const int32_t n = blob.num_chunks(chunk);
  const std::vector<int32_t> indices = chunks_to_send(req.chunk_indices, n);
  const auto interval = std::chrono::duration_cast<SteadyClock::duration>(
      std::chrono::duration<double, std::milli>(cfg_.chunk_interval_ms));
  auto next = SteadyClock::now();
  Chunk c{};
  c.request_id = req.request_id;
  c.snapshot_id = static_cast<int64_t>(blob.contents.snapshot_id);
  c.num_chunks = n;
  c.total_size = static_cast<int64_t>(blob.bytes.size());
  c.blob_hash = blob.hash;
  c.format = blob.format;
  c.compression = blob.compression;
  c.uncompressed_size = blob.raw_size;
  c.num_scans = static_cast<int64_t>(blob.contents.scans);
  c.map_epoch = static_cast<int64_t>(blob.contents.epoch);
  c.chunk_size = static_cast<int32_t>(chunk);
  c.server_id = cfg_.server_id;
  c.client_id = req.client_id;
  for (int32_t i : indices) {
    std::this_thread::sleep_until(next);
    c.utime = now_utime();
    c.chunk_index = i;
    c.offset = static_cast<int64_t>(i) * static_cast<int64_t>(chunk);
    const size_t len = std::min(chunk, blob.bytes.size() - static_cast<size_t>(c.offset));
    c.data.assign(blob.bytes.begin() + c.offset, blob.bytes.begin() + c.offset + static_cast<int64_t>(len));
    c.data_size = static_cast<int32_t>(len);
    loop_.publish(req.reply_channel, c);
    next = SteadyClock::now() + interval;
    std::lock_guard lock(mutex_);
    stats_.chunks_sent++;
  }
}

void MapService::publish_info() {
  octomap_rt::map_info_t m{};
  m.protocol_version = protocol::kProtocolVersion;
  protocol::put_shard_set(cfg_.shard, m);
  m.utime = now_utime();
  {
    std::shared_lock lock(map_.mutex);
    const MapHoldNote note(map_.holders, "map info");
    m.map_version = static_cast<int64_t>(map_.version);
    m.map_epoch = static_cast<int64_t>(map_.epoch);
  }
  m.delta_seq = last_delta_seq_ ? last_delta_seq_() : -1;
  m.resolution = cfg_.resolution;
  for (int k = 0; k < 3; ++k) {
    m.region_min[k] = cfg_.region_min[k];
    m.region_max[k] = cfg_.region_max[k];
  }
  m.server_id = cfg_.server_id;
  m.map_frame = cfg_.map_frame;
  m.chunk_size = static_cast<int32_t>(protocol::kChunkDataBytes);
  // A snapshot of an earlier epoch (before a reset) is not one of this map's states.
  if (const auto b = store_.last_made(); b && static_cast<int64_t>(b->contents.epoch) == m.map_epoch) {
    const SnapshotContents& c = b->contents;
    m.snapshot_id = static_cast<int64_t>(c.snapshot_id);
    m.map_utime = c.map_utime;
    for (int k = 0; k < 3; ++k) {
      m.bbox_min[k] = c.bbox_min[k];
      m.bbox_max[k] = c.bbox_max[k];
    }
    m.format = b->format;
    m.compression = b->compression;
    m.uncompressed_size = b->raw_size;
    m.total_size = static_cast<int64_t>(b->bytes.size());
    m.num_chunks = b->num_chunks(protocol::kChunkDataBytes);
    m.blob_hash = b->hash;
    m.num_scans = static_cast<int64_t>(c.scans);
    for (const auto& [id, seq] : c.producer_last_seq) {
      m.producer_id.push_back(id);
      m.producer_last_seq.push_back(seq);
    }
  }
  m.num_producers = static_cast<int32_t>(m.producer_id.size());
  if (const auto b = store_.last_made()) m.num_producers_total = static_cast<int32_t>(b->contents.producers_total);
  loop_.publish(cfg_.info_channel, m);
}

}  // namespace ort::daemon
