#include "daemon/serving/map_service.h"

#include <chrono>
#include <exception>

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_info_t.hpp"
#include "protocol/ids.h"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
#include "protocol/map_protocol.h"
#include "protocol/version.h"

namespace ort::daemon {
namespace {

using Chunk = octomap_rt::map_chunk_t;
using Clock = std::chrono::steady_clock;

int64_t utime_now() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

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
  {
    std::lock_guard lock(mutex_);
    if (queue_.size() < cfg_.request_queue) {
      queue_.push_back(std::move(req));
      cv_.notify_all();
      return;
    }
  }
  refuse(&req, protocol::RequestRefusal::kBusy, "");
}

void MapService::run() {
  auto next_info = Clock::now();
  std::unique_lock lock(mutex_);
  while (!stop_) {
    cv_.wait_until(lock, next_info, [&] { return stop_ || !queue_.empty(); });
    if (stop_) break;
    if (!queue_.empty()) {
      const octomap_rt::map_request_t req = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      try {
        serve(req);
      } catch (const std::exception& e) {
        log_.error(text("map request ", req.request_id, " failed: ", e.what()));
      }
      lock.lock();
    }
    if (Clock::now() >= next_info) {
      lock.unlock();
      publish_info();
      lock.lock();
      next_info =
          Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg_.info_period_s));
    }
  }
}

void MapService::serve(const octomap_rt::map_request_t& req) {
  protocol::RequestRefusal why = protocol::check_map_request(req);
  if (why != protocol::RequestRefusal::kNone) return refuse(&req, why, "");
  bool took_new = false;
  // snapshot_id: < 0 a fresh snapshot, 0 the latest kept (maybe older than the map), > 0 that one.
  std::shared_ptr<const SnapshotBlob> blob = req.snapshot_id <= 0
                                                 ? store_.latest(map_, req.format, req.snapshot_id < 0, took_new)
                                                 : store_.find(static_cast<uint64_t>(req.snapshot_id), req.format);
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
  if (!req || !protocol::can_reply(*req)) return;  // nowhere safe to answer: ignored (counted)
  Chunk c{};
  c.utime = utime_now();
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
  std::vector<int32_t> indices = req.chunk_indices;
  if (indices.empty())
    for (int32_t i = 0; i < n; ++i) indices.push_back(i);
  const auto interval =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(cfg_.chunk_interval_ms));
  auto next = Clock::now();
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
  c.chunk_size = static_cast<int32_t>(chunk);
  c.server_id = cfg_.server_id;
  c.client_id = req.client_id;
  for (int32_t i : indices) {
    std::this_thread::sleep_until(next);
    c.utime = utime_now();
    c.chunk_index = i;
    c.offset = static_cast<int64_t>(i) * static_cast<int64_t>(chunk);
    const size_t len = std::min(chunk, blob.bytes.size() - static_cast<size_t>(c.offset));
    c.data.assign(blob.bytes.begin() + c.offset, blob.bytes.begin() + c.offset + static_cast<int64_t>(len));
    c.data_size = static_cast<int32_t>(len);
    loop_.publish(req.reply_channel, c);
    next = Clock::now() + interval;
    std::lock_guard lock(mutex_);
    stats_.chunks_sent++;
  }
}

void MapService::publish_info() {
  octomap_rt::map_info_t m{};
  m.protocol_version = protocol::kProtocolVersion;
  m.utime = utime_now();
  {
    std::lock_guard lock(map_.mutex);
    m.map_version = static_cast<int64_t>(map_.version);
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
  if (const auto b = store_.last_made()) {
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
  loop_.publish(cfg_.info_channel, m);
}

}  // namespace ort::daemon
