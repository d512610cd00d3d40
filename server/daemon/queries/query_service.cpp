#include "daemon/queries/query_service.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>

#include "core/clock.h"
#include "core/errors.h"
#include "daemon/map/map_edit_item.h"
#include "daemon/map/map_replica.h"
#include "daemon/map/map_residency.h"
#include "daemon/queries/distance_flags.h"
#include "daemon/queries/edit_audit.h"
#include "daemon/queries/query_footprint.h"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "protocol/channels.h"
#include "protocol/ids.h"
#include "protocol/inbound_checks.h"
#include "query/query_types.h"

namespace ort::daemon {
namespace {

using Reply = octomap_rt::occupancy_reply_t;
using Count = QueryClients::Count;
const std::string kNoClient = "?";
constexpr size_t kMaxParked = 256;  // queries waiting for their map state, all clients
// Longest a batch of queries holds the map for reading (stage 2 may be waiting to write).
constexpr auto kReadTurn = std::chrono::milliseconds(10);
// How long a turn that found no map free to read waits for a new query before asking again.
constexpr auto kTurnRetry = std::chrono::microseconds(500);

// The ack's status for what the pipeline did with an edit.
int8_t ack_status(const MapEditResult& r) {
  switch (r.refusal) {
    case EditRefusal::kNone: return r.ok ? Reply::REPLY_OK : Reply::REPLY_BAD_REQUEST;
    case EditRefusal::kBadRequest: return Reply::REPLY_BAD_REQUEST;
    case EditRefusal::kTooCostly: return Reply::REPLY_REFUSED;
    case EditRefusal::kNotApplied: return Reply::REPLY_NOT_READY;
  }
  return Reply::REPLY_BAD_REQUEST;
}

}  // namespace

QueryService::QueryService(const QueryServiceConfig& cfg, MapState& map, ScanQueue& scans, LcmLoop& loop,
                           std::string server_id, double resolution, Log log)
    : cfg_(cfg),
      map_(map),
      scans_(scans),
      loop_(loop),
      server_id_(std::move(server_id)),
      resolution_(resolution),
      audit_(std::move(log)),
      clients_(cfg.per_client_queue, cfg.max_clients, static_cast<int64_t>(cfg.client_idle_expiry_s * 1e6)),
      gate_({cfg.control_token, static_cast<int64_t>(cfg.edit_window_s * 1e6), cfg.max_edit_nonces}),
      grids_(cfg.grid, cfg.bounds, map, loop, server_id_) {
  DistanceBackend backend = choose_distance_backend(cfg.distance.backend, cfg.distance.device, cfg.distance.threads);
  edt_ = std::move(backend.edt);
  distance_backend_ = std::move(backend.name);
}

QueryService::~QueryService() { stop(); }

void QueryService::open() {
  using namespace octomap_rt;
  subs_.push_back(loop_.subscribe(cfg_.points_channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    on_query<occupancy_query_t>(rb, protocol::check_occupancy_query_bytes);
  }));
  subs_.push_back(loop_.subscribe(cfg_.rays_channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    on_query<ray_query_t>(rb, protocol::check_ray_query_bytes);
  }));
  subs_.push_back(loop_.subscribe(cfg_.boxes_channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    on_query<box_query_t>(rb, protocol::check_box_query_bytes);
  }));
  subs_.push_back(loop_.subscribe(cfg_.grid_channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    on_query<grid_query_t>(rb, protocol::check_grid_query_bytes);
  }));
  subs_.push_back(loop_.subscribe(cfg_.distance_channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    on_query<distance_query_t>(rb, protocol::check_distance_query_bytes);
  }));
  subs_.push_back(loop_.subscribe(
      cfg_.edit_channel, [this](const lcm::ReceiveBuffer& rb, const std::string& channel) { on_edit(rb, channel); }));
}

QueryServiceStats QueryService::service_stats() const {
  QueryServiceStats s;
  s.clients = clients_.snapshot();
  s.refusal_reasons = clients_.refusal_reasons();
  s.grids_published = grids_.published();
  s.turns_deferred = turns_deferred_;
  std::lock_guard lock(field_cache_stats_mutex_);
  s.field_cache = field_cache_stats_;
  return s;
}

void QueryService::start() {
  worker_ = std::thread([this] { run(); });
  grids_.start();
}

void QueryService::cut_running() { cut_now_ = true; }

void QueryService::stop() {
  cut_now_ = true;
  {
    std::lock_guard lock(wake_mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  map_.changed.notify_all();
  if (worker_.joinable()) worker_.join();
  grids_.stop();
}

std::string QueryService::check_addressing(const std::string& client, const std::string& channel) const {
  if (std::string why = protocol::check_client_id(client); !why.empty()) return why;
  if (std::string why = protocol::check_reply_channel(channel); !why.empty()) return why;
  // Replies must not land on the server's own inputs.
  for (const std::string* own : {&cfg_.points_channel, &cfg_.rays_channel, &cfg_.boxes_channel, &cfg_.grid_channel,
                                 &cfg_.edit_channel, &cfg_.distance_channel})
    if (channel == *own) return "reply_channel is one of the server's request channels";
  if (channel == cfg_.grid.channel) return "reply_channel is the server's grid channel";
  if (channel.rfind(cfg_.scan_prefix, 0) == 0 || channel == cfg_.status_channel)
    return "reply_channel is one of the server's scan or status channels";
  return "";
}

template <class Message>
void QueryService::on_query(const lcm::ReceiveBuffer& rb, protocol::WireCheck (*check)(const uint8_t*, size_t)) {
  Message msg;
  if (const protocol::WireCheck c = protocol::decode_checked(rb.data, rb.data_size, check, msg); !c.ok()) {
    const std::string why = protocol::describe(c);  // nobody to answer: the addressing cannot be trusted
    clients_.count(kNoClient, Count::kDropped, why);
    return;
  }
  if (std::string bad = check_addressing(msg.client_id, msg.reply_channel); !bad.empty()) {
    clients_.count(kNoClient, Count::kDropped, bad);
    return;
  }
  clients_.received(msg.client_id, msg.reply_channel, now_utime());
  PendingQuery q{QueryMessage(std::move(msg)), SteadyClock::now(), {}};
  const QueryHeader h = header_of(q.msg);
  const auto* distance_query = std::get_if<octomap_rt::distance_query_t>(&q.msg);
  std::string bad = distance_query ? validate_distance(*distance_query, resolution_, cfg_.distance)
                                   : validate_query(q.msg, resolution_);
  if (bad.empty() && (h.wait_timeout_ms < 0 || h.wait_timeout_ms > cfg_.max_wait_ms))
    bad = "wait_timeout_ms must be in 0.." + std::to_string(cfg_.max_wait_ms);
  if (!bad.empty()) {
    clients_.count(h.client_id, Count::kBad, bad);
    publish(error_reply(q.msg, Reply::REPLY_BAD_REQUEST, bad, {}, server_id_));
    return;
  }
  q.deadline = q.received + std::chrono::milliseconds(h.wait_timeout_ms);
  QueryMessage copy_for_busy = q.msg;
  if (!clients_.push(h.client_id, std::move(q))) {
    publish(error_reply(copy_for_busy, Reply::REPLY_BUSY,
                        "busy: " + std::to_string(cfg_.per_client_queue) + " queries of this client are queued", {},
                        server_id_));
    return;
  }
  wake_.notify_one();
}

void QueryService::on_edit(const lcm::ReceiveBuffer& rb, const std::string& channel) {
  using Edit = octomap_rt::map_edit_t;
  Edit msg;
  std::string why =
      protocol::describe(protocol::decode_checked(rb.data, rb.data_size, protocol::check_map_edit_bytes, msg));
  if (why.empty()) why = check_addressing(msg.client_id, msg.reply_channel);
  if (!why.empty()) {
    clients_.count(kNoClient, Count::kDropped, "map edit: " + why);
    return;
  }
  clients_.received(msg.client_id, msg.reply_channel, now_utime());
  // proven: the sender showed the control token (its audit line is never rate-limited).
  auto ack = [this, msg](const MapEditResult& r, int8_t status, const std::string& error, bool proven) {
    octomap_rt::map_edit_ack_t a;
    a.utime = now_utime();
    a.request_id = msg.request_id;
    a.snapshot_id = static_cast<int64_t>(r.version);
    a.map_epoch = static_cast<int64_t>(r.epoch);
    a.map_utime = r.map_utime;
    a.status = status;
    a.op = msg.op;
    a.voxels = r.voxels;
    a.server_id = server_id_;
    a.client_id = msg.client_id;
    a.error = error;
    clients_.count(msg.client_id, status == Reply::REPLY_OK ? Count::kEditApplied : Count::kEditRefused, error);
    audit_.record(msg, r, status, error, proven);
    loop_.publish(msg.reply_channel, a);
  };
  const EditAdmission admission = gate_.admit(msg, channel, now_utime());
  if (!admission.admitted())
    return ack(MapEditResult{},
               admission.refusal == EditGateRefusal::kTooMany ? Reply::REPLY_BUSY : Reply::REPLY_REFUSED, admission.why,
               admission.authenticated());
  std::string refuse;
  int8_t status = Reply::REPLY_REFUSED;
  if (msg.op != Edit::OP_CLEAR_TO_FREE && msg.op != Edit::OP_CLEAR_TO_UNKNOWN && msg.op != Edit::OP_RESET)
    refuse = "unknown op " + std::to_string(msg.op), status = Reply::REPLY_BAD_REQUEST;
  if (refuse.empty() && (msg.flags & ~Edit::FLAG_INCLUDE_UNKNOWN) != 0)
    refuse = "unknown flags " + std::to_string(msg.flags), status = Reply::REPLY_BAD_REQUEST;
  if (refuse.empty() && msg.op != Edit::OP_RESET) {
    for (int a = 0; a < 3 && refuse.empty(); ++a)
      if (!std::isfinite(msg.box_min[a]) || !std::isfinite(msg.box_max[a]) || msg.box_min[a] > msg.box_max[a])
        refuse = "box corners must be finite with min <= max", status = Reply::REPLY_BAD_REQUEST;
  }
  if (!refuse.empty()) return ack(MapEditResult{}, status, refuse, true);
  auto item = std::make_shared<MapEditItem>();
  item->op = msg.op;
  std::copy(std::begin(msg.box_min), std::end(msg.box_min), item->box_min);
  std::copy(std::begin(msg.box_max), std::end(msg.box_max), item->box_max);
  item->include_unknown = (msg.flags & Edit::FLAG_INCLUDE_UNKNOWN) != 0;
  item->bounds = cfg_.edit_bounds;
  item->done = [ack](const MapEditResult& r) { ack(r, ack_status(r), r.error, true); };
  if (!scans_.push_edit(item)) ack(MapEditResult{}, Reply::REPLY_NOT_READY, "the server is stopping", true);
}

bool QueryService::answer_locked(PendingQuery& q, std::vector<EncodedReplies>& out) {
  MapState& map = *turn_map_;
  const QueryHeader h = header_of(q.msg);
  const MapStamp stamp{static_cast<int64_t>(map.version), map.last_scan_utime, static_cast<int64_t>(map.epoch)};
  // The robot id keys the wait: "" = no wait, whatever wait_seq holds (a default message
  // has wait_seq 0), so a plain query is never parked for a robot that does not exist.
  // Never an older state for a client than one it was answered from (the map of record is
  // never older than the replica): on an older replica it waits for a later turn.
  if (&map != &map_ && map.version < clients_.newest_answered(h.client_id)) return false;
  clients_.answered_at(h.client_id, map.version);
  const bool waits_for_scan = !h.wait_robot_id.empty();
  int64_t applied = -1;
  if (waits_for_scan) {
    auto it = map.newest_scan.find(robot_key(h.wait_robot_id));
    if (it != map.newest_scan.end()) applied = it->second.seq;
  }
  const bool ready = stamp.snapshot_id >= h.min_snapshot_id && (!waits_for_scan || applied >= h.wait_seq);
  if (!ready) {
    if (SteadyClock::now() < q.deadline || &map != &map_) return false;
    const std::string why = "map state " + std::to_string(stamp.snapshot_id) + " (robot '" + h.wait_robot_id +
                            "' applied seq " + std::to_string(applied) + ") did not reach min_snapshot_id " +
                            std::to_string(h.min_snapshot_id) + " / wait_seq " + std::to_string(h.wait_seq) +
                            " within " + std::to_string(h.wait_timeout_ms) + " ms";
    clients_.count(h.client_id, Count::kNotReady, why);
    out.push_back(error_reply(q.msg, Reply::REPLY_NOT_READY, why, stamp, server_id_));
    return true;
  }
  // A query meeting an evicted region waits for the exclusive turn that brings it back.
  if (map.residency && !exclusive_turn_ &&
      map.residency->any_spilled_in(query_footprint(*map.tree, map.residency->grid(), q.msg))) {
    to_restore_.push_back(std::move(q));
    return true;
  }
  // Its own bounds, checked inside the walk: work, time under the lock, the server stopping.
  query::WorkBudget budget;
  budget.max_work = cfg_.bounds.max_work;
  budget.deadline = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                             std::chrono::duration<double, std::milli>(cfg_.bounds.lock_ms));
  budget.stop = &cut_now_;
  try {
    if (const auto* d = std::get_if<octomap_rt::distance_query_t>(&q.msg)) {
      // Only the grid is read here (bounded in cells); the EDT runs after the lock, counted there.
      out.push_back(read_distance(*map.tree, *d, stamp, server_id_, cfg_.distance, edt_,
                                  cfg_.distance.field_cache ? &field_cache_ : nullptr, map_.journal));
      return true;
    }
    out.push_back(answer_query(*map.tree, q.msg, stamp, server_id_, cfg_.bounds, budget, cfg_.shard));
  } catch (const std::exception& e) {  // query::QueryError: a query the map cannot answer
    clients_.count(h.client_id, Count::kBad, e.what());
    out.push_back(error_reply(q.msg, Reply::REPLY_BAD_REQUEST, e.what(), stamp, server_id_));
    return true;
  }
  const EncodedReplies& r = out.back();
  if (r.status == Reply::REPLY_BUSY)
    clients_.count(h.client_id, Count::kBusy, r.error);
  else if (r.status != Reply::REPLY_OK)
    clients_.count(h.client_id, Count::kBad, r.error);
  else
    clients_.count(h.client_id, r.cut ? Count::kAnsweredCut : Count::kAnswered, r.error);
  return true;
}

void QueryService::publish(const EncodedReplies& r) {
  for (size_t i = 0; i < r.messages.size(); ++i) {
    // Paced: a burst of 60 KB datagrams overruns default receive buffers (lcm-1.3.1 notes §3.3).
    if (i > 0 && cfg_.reply_chunk_interval_ms > 0)
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(cfg_.reply_chunk_interval_ms));
    loop_.publish(r.channel, r.messages[i].data(), r.messages[i].size());
  }
}

void QueryService::run() {
  std::vector<PendingQuery> parked;
  for (;;) {
    {
      std::unique_lock lock(wake_mutex_);
      if (stopping_) return;
      if (clients_.queued() == 0)
        wake_.wait_for(lock, parked.empty() ? std::chrono::milliseconds(100) : std::chrono::milliseconds(2),
                       [&] { return stopping_ || clients_.queued() > 0; });
      if (stopping_) return;
    }
    if (parked.empty() && clients_.queued() == 0) continue;
    std::vector<EncodedReplies> out;
    {
      // One turn at the map for every query ready now (within a budget): under a scan
      // backlog a reader gets the lock about once per scan, so each query taking it alone
      // waited a scan per query (on dev: ~20 answered a second, the rest BUSY).
      // While stage 2 holds the map, the read replica when it is free and new enough; a turn
      // with a query past its deadline reads the map of record (the newest state decides).
      const auto now = SteadyClock::now();
      const bool overdue =
          std::any_of(parked.begin(), parked.end(), [&](const PendingQuery& p) { return p.deadline <= now; });
      std::shared_lock<MapMutex> lock;
      if (overdue) {
        lock = std::shared_lock(map_.mutex);
        turn_map_ = &map_;
      } else {
        // The replica is new enough when some waiting client was answered from no newer state.
        uint64_t min_version = clients_.oldest_answered_queued();
        for (const PendingQuery& p : parked)
          min_version = std::min(min_version, clients_.newest_answered(header_of(p.msg).client_id));
        turn_map_ = lock_for_short_read(map_, min_version == UINT64_MAX ? 0 : min_version, lock);
        if (!turn_map_) {
          // Neither is free for the clients waiting now: ask again with those waiting then, so
          // that a client needing a newer state than the replica's never holds up, for all of
          // stage 2's hold, the queries of others that the replica can answer.
          turns_deferred_++;
          std::unique_lock wait(wake_mutex_);
          if (!stopping_) wake_.wait_for(wait, kTurnRetry);
          continue;
        }
      }
      const MapHoldNote note(turn_map_->holders, "query turn");
      const auto turn_end = SteadyClock::now() + kReadTurn;
      for (size_t i = 0; i < parked.size();) {
        if (answer_locked(parked[i], out)) {
          parked[i] = std::move(parked.back());
          parked.pop_back();
        } else {
          ++i;
        }
      }
      while (SteadyClock::now() < turn_end) {
        auto q = clients_.pop(turn_map_ == &map_ ? UINT64_MAX : turn_map_->version);
        if (!q) break;
        if (answer_locked(*q, out)) continue;
        if (parked.size() < kMaxParked) {
          parked.push_back(std::move(*q));
        } else {  // waiting queries are bounded too
          const QueryHeader h = header_of(q->msg);
          clients_.count(h.client_id, Count::kBusy, "busy: too many queries wait for their map state");
          out.push_back(error_reply(q->msg, Reply::REPLY_BUSY, "busy: too many queries wait for their map state", {},
                                    server_id_));
        }
      }
    }
    if (!to_restore_.empty()) answer_restoring(parked, out);
    for (EncodedReplies& r : out) {
      if (r.finish) {
        r.finish(r);
        clients_.count(r.client_id, r.refused.empty() ? Count::kAnswered : Count::kBad, r.refused);
        std::lock_guard lock(field_cache_stats_mutex_);
        field_cache_stats_ = field_cache_.stats();
      }
      publish(r);
    }
  }
}

// The queries that meet evicted regions: under the exclusive lock, their regions come back,
// they are answered, and the bound holds again (daemon/map/map_residency.h).
void QueryService::answer_restoring(std::vector<PendingQuery>& parked, std::vector<EncodedReplies>& out) {
  std::unique_lock lock(map_.mutex);
  const MapHoldNote note(map_.holders, "query restoring regions");
  turn_map_ = &map_;
  exclusive_turn_ = true;
  for (PendingQuery& q : to_restore_) {
    try {
      map_.residency->touch_boxes(*map_.tree, query_footprint(*map_.tree, map_.residency->grid(), q.msg));
    } catch (const std::exception& e) {  // the store could not give a region back
      const QueryHeader h = header_of(q.msg);
      clients_.count(h.client_id, Count::kBusy, e.what());
      out.push_back(error_reply(q.msg, Reply::REPLY_BUSY, std::string("busy: ") + e.what(), {}, server_id_));
      continue;
    }
    if (!answer_locked(q, out) && parked.size() < kMaxParked) parked.push_back(std::move(q));
  }
  to_restore_.clear();
  exclusive_turn_ = false;
  map_.residency->enforce(*map_.tree);
}

}  // namespace ort::daemon
