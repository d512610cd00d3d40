#include "daemon/mapping_server.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <sstream>

#include "core/clock.h"
#include "daemon/kernel_udp_stats.h"
#include "daemon/map_snapshot.h"
#include "daemon/map_store.h"
#include "daemon/run_summary.h"
#include "daemon/server_lcm_url.h"

namespace ort::daemon {
namespace {

using Status = octomap_rt::server_status_t;

uint64_t queue_budget(const ServerConfig& c) {
  return c.queue_budget_bytes ? c.queue_budget_bytes : automatic_queue_budget();
}

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

}  // namespace

MappingServer::MappingServer(const ServerConfig& cfg, std::ostream& log) : MappingServer(cfg, nullptr, log) {}
MappingServer::MappingServer(const ServerConfig& cfg, lcm::LCM& shared, std::ostream& log)
    : MappingServer(cfg, &shared, log) {}

MappingServer::MappingServer(const ServerConfig& cfg, lcm::LCM* shared, std::ostream& log)
    : cfg_(cfg),
      log_(log),
      producers_(literal_prefix(cfg.scan_channels), producer_policy(cfg)),
      queue_(queue_budget(cfg), 8 * queue_budget(cfg)) {
  start_ = std::chrono::steady_clock::now();
  start_utime_ = now_utime();
  host_ = host_name();
  server_id_ = cfg_.server_id.empty() ? "octomap-rt-server@" + host_ : cfg_.server_id;
  // A queue must hold at least one scan of the largest allowed size.
  const uint64_t largest = 12 * cfg_.max_points + 4096;
  if (queue_.per_producer_budget() < largest)
    throw std::runtime_error("queue budget " + std::to_string(queue_.per_producer_budget() >> 20) +
                             " MiB per producer cannot hold one scan of --max-points " + std::to_string(cfg_.max_points));

  load_or_create_map();  // first: a wrong map file fails before any device is opened
  engine_ = std::make_unique<MapEngine>(cfg_.engine, log_to(log_));
  if (!cfg_.applied_log.empty()) map_.order.open_live_log(cfg_.applied_log);

  if (shared) {
    url_ = "(shared LCM instance)";
    loop_ = std::make_unique<LcmLoop>(*shared, log_);
  } else {
    const LcmUrlChoice c = choose_lcm_url(cfg_.lcm_url, cfg_.recv_buf_size);
    url_ = c.url;
    if (!c.warning.empty()) log_ << c.warning << "\n";
    loop_ = std::make_unique<LcmLoop>(url_, log_);
  }
}

MappingServer::~MappingServer() {
  try {
    stop();
  } catch (const std::exception& e) {
    log_ << "octomap-rt-server: error while stopping: " << e.what() << "\n";
  }
}

// A map that is not complete is never loaded (and so never overwritten by a smaller one):
// the server refuses to start, or with --move-corrupt-map-aside keeps it under another name
// and starts anew.
std::unique_ptr<octomap::OcTree> MappingServer::load_checked_map() {
  try {
    return load_map(cfg_.map_path, cfg_.engine.resolution);
  } catch (const MapStoreError& e) {
    if (e.kind() != MapStoreError::Kind::kCorrupt) throw;
    if (!cfg_.move_corrupt_map_aside)
      throw MapStoreError(e.kind(), std::string(e.what()) +
                                        "; the file is left as it is (start with --move-corrupt-map-aside to keep it "
                                        "under another name and start a new map)");
    const std::string aside = move_map_aside(cfg_.map_path);
    if (std::filesystem::exists(cfg_.map_path + ".order")) std::filesystem::rename(cfg_.map_path + ".order", aside + ".order");
    log_ << "octomap-rt-server: warning: " << e.what() << "; moved it to " << aside << " and starting a new map\n";
    return nullptr;
  }
}

void MappingServer::load_or_create_map() {
  const double res = cfg_.engine.resolution;
  if (!cfg_.map_path.empty()) check_map_directory_writable(cfg_.map_path);
  std::unique_ptr<octomap::OcTree> loaded;
  if (!cfg_.map_path.empty() && std::filesystem::exists(cfg_.map_path)) loaded = load_checked_map();
  if (loaded) {
    map_.tree = std::move(loaded);
    apply_sensor_model(*map_.tree, cfg_.engine.sensor);
    std::vector<AppliedEntry> previous;
    const std::string order_path = cfg_.map_path + ".order";
    if (std::filesystem::exists(order_path)) {
      AppliedOrderFile f = read_applied_order(order_path);
      if (f.map_bytes >= 0 && static_cast<uint64_t>(f.map_bytes) != std::filesystem::file_size(cfg_.map_path))
        log_ << "octomap-rt-server: warning: " << order_path
             << " does not belong to this map file (the server stopped between writing the two); its "
             << f.entries.size() << " entries are kept but may not match the map\n";
      previous = std::move(f.entries);
    }
    map_.order.restore(std::move(previous));
    map_.version = map_.order.size();
    saved_version_ = map_.version;
    log_ << "octomap-rt-server: loaded map " << cfg_.map_path << " (" << map_.tree->size() << " nodes, "
         << map_.order.size() << " scans applied before)\n";
  } else {
    map_.tree = std::make_unique<octomap::OcTree>(res);
    apply_sensor_model(*map_.tree, cfg_.engine.sensor);
    if (!cfg_.map_path.empty()) log_ << "octomap-rt-server: new map, will be saved to " << cfg_.map_path << "\n";
  }
}

void MappingServer::start() {
  if (started_) return;
  started_ = true;
  ScanLimits limits;
  limits.max_points = cfg_.max_points;
  limits.resolution = cfg_.engine.resolution;
  open_map_serving();  // the delta observer is in place before the first scan is applied
  pipeline_ = std::make_unique<ScanPipeline>(*engine_, map_, queue_, producers_, metrics_, log_, cfg_.pipeline,
                                             std::chrono::duration<double>(cfg_.latency_bound_s));
  pipeline_->start();
  intake_ = std::make_unique<ScanIntake>(*loop_, cfg_.scan_channels, limits, producers_, queue_, cfg_.lcm_queue_capacity);
  intake_->open();  // services subscribe before the loop starts: 1.3.1's subscribe races with handle
  map_service_->open();
  queries_ = std::make_unique<QueryService>(cfg_.queries, map_, queue_, *loop_, server_id_, cfg_.engine.resolution);
  queries_->open();
  loop_->start();
  raw_publisher_ = std::make_unique<OctomapRawPublisher>(cfg_.octomap_raw, map_, *loop_, log_);
  raw_publisher_->start();
  map_service_->start();
  queries_->start();
  status_thread_ = std::thread([this] { run_status_loop(); });
  if (!cfg_.map_path.empty() && cfg_.save_interval_s > 0) save_thread_ = std::thread([this] { run_save_loop(); });
  set_state(Status::STATE_RUNNING, "serving " + cfg_.scan_channels);
}

void MappingServer::open_map_serving() {
  if (cfg_.delta_rate_hz > 0) {
    DeltaConfig d;
    d.channel = cfg_.map_delta_channel;
    d.max_rate_hz = cfg_.delta_rate_hz;
    d.exact = cfg_.delta_exact;
    d.zstd_level = cfg_.snapshot_zstd_level;
    d.part_interval_ms = cfg_.chunk_interval_ms;
    d.server_id = server_id_;
    d.resolution = cfg_.engine.resolution;
    deltas_ = std::make_unique<DeltaPublisher>(
        *loop_, d, [this] { return map_service_ ? map_service_->stats().latest_snapshot_id : -1; }, log_);
    map_.observer = deltas_.get();
    deltas_->start(map_.version);
  }
  MapServiceConfig m;
  m.request_channel = cfg_.map_request_channel;
  m.info_channel = cfg_.map_info_channel;
  m.snapshots = SnapshotPolicy{cfg_.snapshots_kept, cfg_.snapshot_zstd_level, cfg_.snapshot_min_interval_s};
  m.chunk_interval_ms = cfg_.chunk_interval_ms;
  m.server_id = server_id_;
  m.resolution = cfg_.engine.resolution;
  // This server maps the whole key space of its tree (one region; sharding would narrow it).
  const double half = 32768.0 * cfg_.engine.resolution;
  for (int k = 0; k < 3; ++k) {
    m.region_min[k] = -half;
    m.region_max[k] = half;
  }
  map_service_ = std::make_unique<MapService>(*loop_, map_, m, [this] { return deltas_ ? deltas_->last_seq() : -1; },
                                              log_);
}

bool MappingServer::stop() {
  if (!started_ || stopped_) return final_save_error_.empty();
  stopped_ = true;
  set_state(Status::STATE_STOPPING, "stopping: intake closed, draining queued scans");
  intake_->close();
  queue_.close();
  drain_until_deadline();
  pipeline_->join();
  if (deltas_) deltas_->stop();  // sends the last change set
  map_.observer = nullptr;
  {
    std::lock_guard lock(state_mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (save_thread_.joinable()) save_thread_.join();
  if (!cfg_.map_path.empty()) {
    set_state(Status::STATE_STOPPING, "stopping: saving the map");
    // Nothing may throw before the threads below are joined: a failed final save is
    // reported (log, summary, status, exit status), not thrown.
    try {
      save(true);
    } catch (const std::exception& e) {
      final_save_error_ = e.what();
      log_ << "octomap-rt-server: error: the final save failed (the previous map file is intact): " << e.what() << "\n";
    }
  }
  set_state(Status::STATE_STOPPING, final_save_error_.empty() ? "stopped" : "stopped; the final save failed: " + final_save_error_);
  {
    std::lock_guard lock(state_mutex_);
    status_exit_ = true;
  }
  wake_.notify_all();
  if (status_thread_.joinable()) status_thread_.join();
  raw_publisher_->stop();
  map_service_->stop();
  if (queries_) queries_->stop();
  loop_->stop();
  return final_save_error_.empty();
}

// The bounded drain: queued scans go through the pipeline until the queue is empty or the
// deadline passes; what is still queued then is dropped, counted ("left at shutdown").
// Scans already in the pipeline (at most two) are finished either way.
void MappingServer::drain_until_deadline() {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(std::max(0.0, cfg_.drain_timeout_s)));
  while (queue_.depth() > 0 && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const std::vector<QueuedScan> left = queue_.take_all();
  for (const QueuedScan& s : left) producers_.count_dropped_in_flight(s.producer, Reject::kLeftAtShutdown);
  if (!left.empty())
    log_ << "octomap-rt-server: drain deadline (" << cfg_.drain_timeout_s << " s) passed: " << left.size()
         << " queued scans dropped (left at shutdown); saving the map as applied\n";
}

void MappingServer::set_state(int8_t state, std::string message) {
  {
    std::lock_guard lock(state_mutex_);
    state_ = state;
    message_ = std::move(message);
    state_changed_ = true;
  }
  wake_.notify_all();
}

void MappingServer::save(bool force) {
  if (cfg_.map_path.empty()) return;
  std::lock_guard save_lock(save_mutex_);
  const auto t0 = std::chrono::steady_clock::now();
  // Copy under the map lock (a state between two whole scans); serialize and write outside it.
  std::optional<MapCopy> copy = force ? std::optional<MapCopy>(copy_map(map_)) : copy_map_if_changed(map_, saved_version_);
  if (!copy) return;
  const std::string bytes = serialize_map(*copy->tree);
  copy->tree.reset();
  const std::vector<AppliedEntry> order = map_.order.entries(copy->scans);
  // Map first: if we die between the two renames the order file is the older one, which
  // the next start detects by its map_bytes line.
  write_file_atomically(cfg_.map_path, bytes);
  write_file_atomically(cfg_.map_path + ".order", format_applied_order(order, bytes.size()));
  saved_version_ = copy->version;
  saves_++;
  last_save_utime_ = now_utime();
  max_save_lock_ms_ = std::max(max_save_lock_ms_, copy->lock_ms);
  last_save_ms_ = ms_since(t0);
}

void MappingServer::run_save_loop() {
  const auto period = std::chrono::duration<double>(cfg_.save_interval_s);
  std::unique_lock lock(state_mutex_);
  while (!stopping_) {
    if (wake_.wait_for(lock, period, [&] { return stopping_; })) break;
    lock.unlock();
    std::string error;
    try {
      save(false);
    } catch (const std::exception& e) {
      error = e.what();
      log_ << "octomap-rt-server: save failed (the previous map file is intact): " << error << "\n";
    }
    lock.lock();
    last_save_error_ = error;  // the status is DEGRADED while it is set
  }
}

void MappingServer::run_status_loop() {
  const auto period = std::chrono::duration<double>(cfg_.status_period_s);
  std::unique_lock lock(state_mutex_);
  for (;;) {
    wake_.wait_for(lock, period, [&] { return state_changed_ || status_exit_; });
    const bool exit = status_exit_;
    state_changed_ = false;
    lock.unlock();
    try {
      publish_status();
    } catch (const std::exception& e) {
      log_ << "octomap-rt-server: status failed: " << e.what() << "\n";
    }
    lock.lock();
    if (exit) return;
  }
}

StatusInputs MappingServer::gather_status() {
  StatusInputs in;
  in.utime = now_utime();
  in.start_utime = start_utime_;
  in.uptime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  in.pid = static_cast<int32_t>(::getpid());
  in.server_id = server_id_;
  in.host = host_;
  in.backend = to_string(engine_->backend().kind());
  in.device = engine_->backend().device_name();
  in.map_path = cfg_.map_path;
  in.queue_policy = queue_.policy();
  in.pipelined = cfg_.pipeline;
  in.resolution = cfg_.engine.resolution;
  {
    // size() is O(1); the leaf count (and memoryUsage(), which needs it) walks the whole
    // tree under the map lock, stalling stage 2. So on big maps it is refreshed at most
    // every 10 s and memory is computed from the cached leaf count with OctoMap's formula.
    // The status never waits long for the map lock: a stage stuck while holding it must
    // still be reported (DEGRADED), so after ~100 ms the last figures are used again.
    std::shared_lock lock(map_.mutex, std::defer_lock);
    for (int i = 0; i < 100 && !lock.try_lock(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (lock.owns_lock()) {
      const octomap::OcTree& t = *map_.tree;
      const auto now = std::chrono::steady_clock::now();
      if (t.size() <= 1'000'000 || now - leaves_time_ > std::chrono::seconds(10)) {
        cached_leaves_ = t.getNumLeafNodes();
        leaves_time_ = now;
      }
      const size_t leaves = std::min(cached_leaves_.load(), t.size());
      cached_nodes_ = static_cast<int64_t>(t.size());
      cached_version_ = static_cast<int64_t>(map_.version);
      cached_memory_ = static_cast<int64_t>(sizeof(octomap::OcTree) + t.memoryUsageNode() * t.size() +
                                            (t.size() - leaves) * sizeof(octomap::OcTreeNode* [8]));
    }
    in.map_version = cached_version_;
    in.num_nodes = cached_nodes_;
    in.num_leaf_nodes = static_cast<int64_t>(std::min<size_t>(cached_leaves_.load(), static_cast<size_t>(cached_nodes_.load())));
    in.memory_bytes = cached_memory_;
  }
  in.queue_depth = static_cast<int32_t>(queue_.depth());
  in.queue_bytes = static_cast<int64_t>(queue_.bytes());
  in.queue_budget_bytes = static_cast<int64_t>(queue_.per_producer_budget());
  in.shot_depth = pipeline_ ? static_cast<int32_t>(pipeline_->shot_depth()) : 0;
  in.kernel_rcvbuf_errors = read_udp_rcvbuf_errors();
  in.socket_rcvbuf_drops = read_own_udp_drops();
  in.map_saves = saves_;
  if (map_service_) {
    const MapServiceStats ms = map_service_->stats();
    in.latest_snapshot_id = std::max<int64_t>(ms.latest_snapshot_id, 0);
    in.requests_served = ms.requests_served;
    in.requests_rejected = ms.requests_rejected;
    in.snapshots_taken = ms.snapshots_taken;
    in.chunks_sent = ms.chunks_sent;
  }
  if (deltas_) {
    const DeltaStats ds = deltas_->stats();
    in.deltas_sent = ds.messages;
    in.last_delta_seq = ds.last_seq;
  }
  in.last_save_utime = last_save_utime_;
  if (queries_) in.queries = queries_->service_stats();
  in.metrics = metrics_.snapshot();
  in.producers = producers_.snapshot();
  for (size_t i = 0; i < in.producers.size(); ++i)
    in.producer_queue_bytes.push_back(static_cast<int64_t>(queue_.producer_bytes(i)));
  std::lock_guard lock(state_mutex_);
  in.state = state_;
  in.message = message_;
  in.seq = status_seq_;
  return in;
}

octomap_rt::server_status_t MappingServer::status() { return make_status(gather_status()); }

void MappingServer::publish_status() {
  StatusInputs in = gather_status();
  const std::string why = degraded_causes(in);
  {
    std::lock_guard lock(state_mutex_);
    if (loop_->failed()) {
      state_ = Status::STATE_ERROR;
      message_ = "LCM intake failed; no scans are received";
    } else if (state_ == Status::STATE_RUNNING && !why.empty()) {
      state_ = Status::STATE_DEGRADED;
      message_ = "degraded: " + why;
    } else if (state_ == Status::STATE_DEGRADED) {
      if (why.empty()) {
        state_ = Status::STATE_RUNNING;
        message_ = "serving " + cfg_.scan_channels;
      } else {
        message_ = "degraded: " + why;
      }
    }
    in.state = state_;
    in.message = message_;
    in.seq = status_seq_++;
  }
  // The viewers' map cut or skipped for its size: said in every status.
  if (const std::string note = raw_publisher_ ? raw_publisher_->note() : ""; !note.empty()) in.message += "; " + note;
  const octomap_rt::server_status_t msg = make_status(in);
  loop_->publish(cfg_.status_channel, msg);
}

// Why the server is DEGRADED now ("" when it is not): trouble in the last status period
// (drops, rejections, kernel UDP drops) and trouble that lasts (a failing save, a stage
// stuck on one scan, a queue over its bound, latency over its bound).
std::string MappingServer::degraded_causes(const StatusInputs& in) {
  int64_t drops = 0, rejects = 0;
  for (const ProducerStats& p : in.producers) {
    drops += p.dropped;
    rejects += p.rejected;
  }
  std::ostringstream why;
  {
    std::lock_guard lock(state_mutex_);
    if (!last_save_error_.empty()) why << "save failing (" << last_save_error_ << "); ";
  }
  const double busy_s = pipeline_ ? std::chrono::duration<double>(pipeline_->longest_busy()).count() : 0.0;
  if (cfg_.stuck_stage_s > 0 && busy_s > cfg_.stuck_stage_s)
    why << "stage stuck (" << static_cast<int>(busy_s) << " s on one scan); ";
  const double age_s = std::chrono::duration<double>(queue_.oldest_age()).count();
  if (queue_.bytes() > queue_.total_budget() * 9 / 10 || (cfg_.latency_bound_s > 0 && age_s > cfg_.latency_bound_s))
    why << "queue over its bound (" << (queue_.bytes() >> 20) << " MiB, oldest " << age_s << " s); ";
  if (cfg_.latency_bound_s > 0 && in.metrics.e2e_p99 > cfg_.latency_bound_s * 1000.0)
    why << "latency over its bound (p99 " << in.metrics.e2e_p99 / 1000.0 << " s > " << cfg_.latency_bound_s << " s); ";
  if (drops > last_drops_) why << (drops - last_drops_) << " scans dropped; ";
  if (rejects > last_rejects_) why << (rejects - last_rejects_) << " scans rejected; ";
  // The server's own socket drops when known (the namespace-wide count includes clients).
  const int64_t kernel = in.socket_rcvbuf_drops >= 0 ? in.socket_rcvbuf_drops : in.kernel_rcvbuf_errors;
  if (last_kernel_errors_ >= 0 && kernel > last_kernel_errors_)
    why << (kernel - last_kernel_errors_) << " UDP datagrams dropped by the kernel on the server's socket (receive buffer full); ";
  last_drops_ = drops;
  last_rejects_ = rejects;
  last_kernel_errors_ = kernel;
  return why.str();
}

void MappingServer::print_summary(std::ostream& out) {
  RunSummaryInputs in;
  in.status = gather_status();
  in.scans_in_map = map_.order.size();
  in.applied_log = cfg_.applied_log;
  in.last_save_ms = last_save_ms_;
  in.max_save_lock_ms = max_save_lock_ms_;
  if (map_service_) in.map_service = map_service_->stats();
  if (deltas_) in.deltas = deltas_->stats();
  in.deltas_on = deltas_ != nullptr;
  in.final_save_error = final_save_error_;
  print_run_summary(out, in);
  print_query_summary(out, query_stats());
}

}  // namespace ort::daemon
