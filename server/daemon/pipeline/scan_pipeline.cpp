#include "daemon/pipeline/scan_pipeline.h"

#include <algorithm>
#include <cctype>
#include <optional>
#include <ostream>

#include "core/clock.h"
#include "daemon/intake/scan_to_map.h"
#include "daemon/map/change_journal.h"
#include "daemon/map/map_identity.h"
#include "daemon/map/map_replica.h"
#include "daemon/map/map_residency.h"

namespace ort::daemon {
namespace {
// Keeps the robots_seen table within its bound: the stalest robot goes first.
void note_robot_seen(MapState& map, const std::string& robot, const octomap::point3d& origin) {
  map.robots_seen[robot] = MapState::RobotSeen{origin, SteadyClock::now()};
  if (map.robots_seen.size() <= MapState::kMaxRobotsSeen) return;
  auto stalest = map.robots_seen.begin();
  for (auto it = map.robots_seen.begin(); it != map.robots_seen.end(); ++it)
    if (it->second.applied < stalest->second.applied) stalest = it;
  map.robots_seen.erase(stalest);
}
}  // namespace

ScanPipeline::ScanPipeline(MapEngine& engine, MapState& map, ScanQueue& queue, ProducerRegistry& producers,
                           PipelineMetrics& metrics, Log log, bool pipelined,
                           std::chrono::duration<double> max_queue_age, const PointFilters& filters)
    : engine_(engine),
      map_(map),
      queue_(queue),
      producers_(producers),
      metrics_(metrics),
      log_(std::move(log)),
      pipelined_(pipelined),
      max_queue_age_(max_queue_age),
      filters_(filters) {}

void ScanPipeline::set_busy(int stage, bool busy) {
  busy_since_ns_[stage] = busy ? std::max<int64_t>(1, SteadyClock::now().time_since_epoch().count()) : 0;
}

SteadyClock::duration ScanPipeline::longest_busy(SteadyClock::time_point now) const {
  SteadyClock::duration longest = SteadyClock::duration::zero();
  for (const auto& since : busy_since_ns_) {
    const int64_t t = since;
    if (t) longest = std::max(longest, now - SteadyClock::time_point(SteadyClock::duration(t)));
  }
  return longest;
}

bool ScanPipeline::shed_if_stale(const QueuedScan& item) {
  // An edit is never shed for age: its sender waits for the ack, and it belongs to no producer.
  if (item.edit) return false;
  if (max_queue_age_.count() <= 0 || SteadyClock::now() - item.received <= max_queue_age_) return false;
  producers_.count_dropped_in_flight(item.producer, item.passed_over ? Reject::kOverShare : Reject::kOverLatencyBound);
  shed_++;
  return true;
}

ScanPipeline::~ScanPipeline() {
  queue_.close();
  join();
}

void ScanPipeline::start() {
  if (pipelined_) {
    stage1_ = std::thread([this] { run_stage1(); });
    stage2_ = std::thread([this] { run_stage2(); });
  } else {
    stage1_ = std::thread([this] { run_sequential(); });
  }
}

void ScanPipeline::join() {
  if (stage1_.joinable()) stage1_.join();
  if (stage2_.joinable()) stage2_.join();
}

void ScanPipeline::refuse_cost(size_t producer, Reject why, const std::string& detail) {
  if (cost_refusals_logged_++ < 10) log_.warning(text("scan refused (", to_string(why), "): ", detail));
  producers_.count_rejected_in_flight(producer, why);
}

void ScanPipeline::reject(size_t producer, Reject why, const char* what) {
  if (why == Reject::kEngineError && engine_errors_++ < 10) log_.error(text("engine error: ", what));
  producers_.count_rejected_in_flight(producer, why);
}

bool ScanPipeline::shoot(QueuedScan& item, ShotJob& job) {
  job.arrival = item.arrival;
  if (item.edit) {  // edits pass stage 1 untouched
    job.edit = std::move(item.edit);
    return true;
  }
  set_busy(0, true);
  const double token = metrics_.overlap().begin(0);
  const auto t0 = SteadyClock::now();
  const SteadyClock::time_point decoded = item.decoded == SteadyClock::time_point{} ? item.received : item.decoded;
  job.waits.decode_ms = ms_between(item.received, decoded);
  job.waits.queue_ms = ms_between(decoded, t0);
  bool ok = true;
  try {
    std::string detail;
    job.origin = scan_pose(item.msg).trans();
    const double max_range = effective_max_range(item.msg.max_range, engine_.options().max_range);
    // What the scan may cost is decided before any ray is shot: per point first (the rays'
    // mean length), then the stages' time it is predicted to take (while others wait), then
    // where the robot has been and its allowance.
    Reject refusal =
        gate_.admit_rays(ray_lengths(item.msg, max_range, engine_.options().resolution).mean_voxels(), detail);
    // The per-scan time bound is for producers without history (fresh ids are free to make);
    // an established robot's scans are bounded by its share, and a slow machine's overload
    // drops them over their share, never refuses them for their cost.
    if (refusal == Reject::kNone && !item.shared_refusal.empty()) {  // a robot streams: the queue's bound
      refusal = Reject::kPredictedTooSlow;
      detail = item.shared_refusal;
    }
    if (refusal == Reject::kNone && item.share_class == kNewProducersClass)
      refusal = gate_.admit_stage_time(item.predicted, item.others_stream, detail);
    if (refusal == Reject::kNone) refusal = gate_.admit_origin(item.producer, job.origin, t0, detail);
    if (refusal != Reject::kNone) {
      refuse_cost(item.producer, refusal, detail);
      metrics_.overlap().end(0, token);
      set_busy(0, false);
      queue_.charge(item.arrival, ms_since(t0));
      return false;
    }
    if (filters_.active()) {
      job.filtered = shoot_filtered(engine_, item.msg, filters_, max_range, filter_scratch_, job.shot);
    } else if (item.msg.points_frame == octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME) {
      // The message's floats as they are: a back end preparing on its device copies them
      // straight into its upload buffer (transformed on the GPU where it can).
      const octomap::pose6d pose = scan_pose(item.msg);
      const std::span<const float> xyz(item.msg.xyz.data(), item.msg.xyz.size() - item.msg.xyz.size() % 3);
      job.origin = pose.trans();
      engine_.shoot_posed_xyz(pose, pose.trans(), xyz, max_range, job.shot);
    } else {
      const PosedMessageScan scan = to_posed_scan(item.msg);
      const std::span<const octomap::point3d> pts(scan.points.size() ? &scan.points[0] : nullptr, scan.points.size());
      job.origin = scan.origin;
      engine_.shoot(scan.origin, pts, max_range, job.shot);
    }
    if (!job.shot.prepare.origin_ok) {
      reject(item.producer, Reject::kOriginOutsideMap, "");
      ok = false;
    } else if (job.shot.shoot.walk_overruns && overrun_warnings_++ < 10) {
      // The shaders' step guard stopped a ray: the scan is applied, but this must never happen.
      log_.warning(text(job.shot.shoot.walk_overruns, " ray walks hit the GPU step guard"));
    }
    if (ok && job.shot.refusal != ShotRefusal::kNone) {
      reject(item.producer, job.shot.refusal == ShotRefusal::kRayTooLong ? Reject::kRayTooLong : Reject::kTooMuchWork,
             "");
      ok = false;
    }
    if (ok) shard_.keep_owned(job.shot);  // a shard's cost is what it applies
    if (ok) {
      if (const Reject why = gate_.admit_voxels(job.shot.free_voxels + job.shot.occupied_voxels, detail);
          why != Reject::kNone) {
        refuse_cost(item.producer, why, detail);
        ok = false;
      }
    }
  } catch (const std::exception& e) {
    reject(item.producer, Reject::kEngineError, e.what());
    ok = false;
  }
  metrics_.overlap().end(0, token);
  set_busy(0, false);
  job.producer = item.producer;
  job.share_class = item.share_class;
  job.robot_id = item.msg.robot_id;
  job.seq = item.msg.seq;
  job.utime = item.msg.utime;
  job.points = item.msg.num_xyz / 3;
  job.received = item.received;
  job.shot_at = SteadyClock::now();
  job.shoot_ms = ms_between(t0, job.shot_at);
  queue_.charge(item.arrival, job.shoot_ms);
  return ok;
}

void ScanPipeline::apply_edit(MapEditItem& edit) {
  if (shard_.active() && edit.include_unknown)  // it would mark other shards' regions free
    return refuse_map_edit(edit, EditRefusal::kBadRequest,
                           "a shard does not mark unknown space free (--include-unknown): it would map other "
                           "shards' regions");
  MapEditResult r;
  try {
    std::unique_lock lock(map_.mutex);
    const auto locked = SteadyClock::now();
    const MapHoldNote note(map_.holders, "map edit");
    r = apply_map_edit(map_, edit);
    r.locked_ms = ms_since(locked);
  } catch (const std::exception& e) {
    r.ok = false;
    r.refusal = EditRefusal::kBadRequest;
    r.error = e.what();
  }
  map_.changed.notify_all();
  if (edit.done) edit.done(r);
}

namespace {

// What preparation skipped of a scan's points, by the daemon's reasons (every back end
// prepares by the same rules: core/prepare_scan.h, shaders/prepare_rays.comp).
PointDropCounts point_drops(const PrepareReport& r, const FilterCounts& f) {
  PointDropCounts d{};
  d[static_cast<size_t>(PointDrop::kNonFinite)] = static_cast<int64_t>(r.nonfinite);
  d[static_cast<size_t>(PointDrop::kOutsideKeyRange)] = static_cast<int64_t>(r.out_of_range);
  d[static_cast<size_t>(PointDrop::kDegenerateRay)] = static_cast<int64_t>(r.degenerate);
  d[static_cast<size_t>(PointDrop::kOutsideSensorBox)] = static_cast<int64_t>(f.outside_sensor_box);
  d[static_cast<size_t>(PointDrop::kOutsideMapBox)] = static_cast<int64_t>(f.outside_map_box);
  d[static_cast<size_t>(PointDrop::kBelowMinRange)] = static_cast<int64_t>(f.below_min_range);
  return d;
}

}  // namespace

bool ScanPipeline::apply(ShotJob& job) {
  if (job.edit) {
    apply_edit(*job.edit);
    return false;
  }
  const double token = metrics_.overlap().begin(1);
  const auto t0 = SteadyClock::now();
  job.waits.handoff_ms = ms_between(job.shot_at, t0);
  set_busy(1, true);
  std::string detail;
  if (const Reject why = gate_.admit_allowance(job.producer, t0, detail); why != Reject::kNone) {
    set_busy(1, false);
    metrics_.overlap().end(1, token);
    refuse_cost(job.producer, why, detail);
    return false;
  }
  Stage2Parts parts;
  int64_t new_nodes = 0;
  try {
    // Room in the read replica's queue first, without the map lock: while the replica is
    // behind, queries go on reading the map of record instead of waiting with stage 2.
    if (map_.replica) map_.replica->wait_for_room(job.shot.voxels.size());
    std::lock_guard lock(map_.mutex);
    const auto locked = SteadyClock::now();
    // The holder it waited for let go of the lock last (daemon/map/map_lock_holders.h).
    const char* waited_for = map_.holders.last_released();
    const MapHoldNote note(map_.holders, "scan update (stage 2)");
    // Spilled regions the scan updates come back first (daemon/map/map_residency.h).
    if (std::string why; map_.residency && !map_.residency->touch_scan(*map_.tree, job.shot.voxels, why, job.robot_id))
      throw std::runtime_error(why);
    const auto nodes_before = static_cast<int64_t>(map_.tree->size());
    const bool log_changes = map_.observer || (map_.journal && map_.journal->armed());
    const std::optional<int64_t> leaf_change = engine_.apply(job.shot, *map_.tree, log_changes ? &changes_ : nullptr);
    new_nodes = static_cast<int64_t>(map_.tree->size()) - nodes_before;
    // A scan stamped in the far future must not pin the map's time there: its utime in the
    // map (order, snapshots, replies) is bounded by the daemon's clock plus the clock skew
    // robots may have.
    const int64_t utime = std::min(job.utime, now_utime() + gate_.max_future_us());
    map_.order.append(AppliedEntry{job.robot_id, job.seq, utime});
    map_.scans++;
    count_map_change(map_, leaf_change);
    map_.last_scan_utime = std::max(map_.last_scan_utime, utime);
    map_.last_scan_origin = job.origin;
    const auto updated = SteadyClock::now();
    // The journal reads the log before the observer takes it over.
    if (log_changes && map_.journal) map_.journal->applied(changes_, map_.tree->getOccupancyThresLog(), map_.version);
    if (map_.observer) map_.observer->applied(changes_, *map_.tree, map_.version);
    const std::string robot = robot_key(job.robot_id);
    map_.newest_scan[robot] = MapState::NewestScan{job.robot_id, job.seq, map_.scans};
    note_robot_seen(map_, robot, job.origin);
    if (map_.residency) map_.residency->enforce(*map_.tree);
    if (map_.replica) map_.replica->scan_applied(job.shot.voxels, map_, robot);
    parts = {ms_between(t0, locked), ms_between(locked, updated), ms_between(updated, SteadyClock::now()), waited_for};
  } catch (const std::exception& e) {
    set_busy(1, false);
    metrics_.overlap().end(1, token);
    queue_.charge(job.arrival, ms_since(t0));
    reject(job.producer, Reject::kEngineError, e.what());
    return false;
  }
  set_busy(1, false);
  map_.changed.notify_all();
  const auto t1 = SteadyClock::now();
  queue_.charge(job.arrival, ms_between(t0, t1));
  const double overlap_s = metrics_.overlap().end(1, token);
  AppliedTiming t;
  t.shoot_ms = job.shoot_ms;
  t.octree_ms = ms_between(t0, t1);
  t.end_to_end_ms = ms_between(job.received, t1);
  t.points = job.points;
  t.overlapped = overlap_s > 0;
  t.waits = job.waits;
  t.stage1 = job.shot.shoot.times;
  t.stage1.octree_ms = 0;  // stage 2's
  t.stage2 = parts;
  t.robot_id = job.robot_id;
  t.seq = job.seq;
  t.received = job.received;
  t.voxels = job.shot.free_voxels + job.shot.occupied_voxels;
  t.new_nodes = new_nodes;
  metrics_.record(t);
  gate_.applied(job.producer, new_nodes, t1);
  producers_.count_applied(job.producer, static_cast<int64_t>(job.shot.prepare.rays), t.end_to_end_ms,
                           point_drops(job.shot.prepare, job.filtered),
                           static_cast<int64_t>(job.shot.prepare.read_as_zero));
  return true;
}

// Every scan the queue hands out leaves it again exactly once (ScanQueue::leave), when it has
// left the stages: its class's next scan may then be served while another class streams.
void ScanPipeline::run_stage1() {
  while (auto item = queue_.pop()) {
    ShotJob job;
    if (!shed_if_stale(*item) && shoot(*item, job)) {
      handoff_.push(std::move(job));
    } else {
      queue_.leave(*item);
    }
  }
  handoff_.close();
}

void ScanPipeline::run_stage2() {
  while (auto job = handoff_.pop()) {
    const bool applied = apply(*job);
    queue_.leave(job->arrival, applied);
  }
}

void ScanPipeline::run_sequential() {
  while (auto item = queue_.pop()) {
    ShotJob job;
    if (!shed_if_stale(*item) && shoot(*item, job)) {
      const bool applied = apply(job);
      queue_.leave(job.arrival, applied);
    } else {
      queue_.leave(*item);
    }
  }
}

}  // namespace ort::daemon
