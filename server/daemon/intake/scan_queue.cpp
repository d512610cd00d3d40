#include "daemon/intake/scan_queue.h"

#include <algorithm>
#include <iterator>
#include <string>

#include "core/clock.h"

namespace ort::daemon {

size_t queued_bytes(const octomap_rt::scan_t& msg) {
  return sizeof(QueuedScan) + msg.xyz.capacity() * sizeof(float) + msg.robot_id.size() + msg.map_frame.size();
}

ScanQueue::ScanQueue(uint64_t per_producer_budget, uint64_t total_budget, bool fair, double shared_class_share,
                     SharedClassBounds shared_bounds)
    : shared_budget_(shared_bounds),
      per_producer_budget_(per_producer_budget),
      total_budget_(total_budget),
      fair_(fair),
      // A share of nothing would never be served; NaN would compare false everywhere.
      shared_class_share_(shared_class_share >= 1e-3 && shared_class_share <= 1e3 ? shared_class_share : 1.0) {}

ScanQueue::ShareClass& ScanQueue::class_named(size_t key) {
  auto [it, made] = classes_.try_emplace(key);
  if (made) it->second.share = key == kNewProducersClass ? shared_class_share_ : 1.0;
  return it->second;
}

size_t ScanQueue::class_for(const QueuedScan& s) const {
  return fair_ && s.established ? s.producer : kNewProducersClass;
}

void ScanQueue::move_to_own_class(size_t producer) {
  // Its scans still waiting in the shared class come along, in their order, so that its
  // scans leave in its order. Waiting for them to leave the shared class first kept a robot
  // there for as long as a flood of fresh ids kept that class's backlog (it never emptied).
  ShareClass& shared = class_named(kNewProducersClass);
  ShareClass& own = class_named(producer);
  if (own.scans.empty()) own.used_ms = std::max(own.used_ms, virtual_ms_);
  for (auto it = shared.scans.begin(); it != shared.scans.end();) {
    if (it->producer != producer) {
      ++it;
      continue;
    }
    shared.bytes -= it->bytes;
    own.bytes += it->bytes;
    it->share_class = producer;
    it->deferrals_at_push = own.deferrals;
    own.scans.push_back(std::move(*it));
    it = shared.scans.erase(it);
  }
  new_class_depth_[producer] = 0;
}

bool ScanQueue::try_push(QueuedScan&& s) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return false;
    if (s.producer >= bytes_by_producer_.size()) {
      bytes_by_producer_.resize(s.producer + 1, 0);
      depth_by_producer_.resize(s.producer + 1, 0);
      new_class_depth_.resize(s.producer + 1, 0);
      served_by_producer_.resize(s.producer + 1);
    }
    if (bytes_by_producer_[s.producer] + s.bytes > per_producer_budget_) return false;
    if (total_bytes_ + s.bytes > total_budget_) return false;
    const size_t cls = class_for(s);
    if (cls != kNewProducersClass && new_class_depth_[s.producer] > 0) move_to_own_class(s.producer);
    ShareClass& c = class_named(cls);
    // Fresh ids are free to make: together they hold what one producer may.
    if (fair_ && cls == kNewProducersClass && c.bytes + s.bytes > per_producer_budget_) return false;
    if (c.scans.empty()) c.used_ms = std::max(c.used_ms, virtual_ms_);  // no credit saved while idle
    bytes_by_producer_[s.producer] += s.bytes;
    depth_by_producer_[s.producer]++;
    if (cls == kNewProducersClass) new_class_depth_[s.producer]++;
    total_bytes_ += s.bytes;
    c.bytes += s.bytes;
    depth_++;
    s.share_class = cls;
    s.deferrals_at_push = c.deferrals;
    s.arrival = next_arrival_++;
    c.scans.push_back(std::move(s));
  }
  ready_.notify_one();
  return true;
}

bool ScanQueue::push_edit(std::shared_ptr<MapEditItem> edit) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return false;
    QueuedScan s;
    s.edit = std::move(edit);
    s.received = SteadyClock::now();
    s.arrival = next_arrival_++;
    edits_.push_back(std::move(s));
  }
  ready_.notify_one();
  return true;
}

bool ScanQueue::empty_locked() const { return depth_ == 0 && edits_.empty(); }

bool ScanQueue::others_stream(size_t producer, SteadyClock::time_point now) const {
  for (size_t p = 0; p < depth_by_producer_.size(); ++p)
    if (p != producer && (depth_by_producer_[p] > 0 || (served_by_producer_[p] != SteadyClock::time_point{} &&
                                                        now - served_by_producer_[p] < kStreamingWindow)))
      return true;
  for (const auto& [arrival, t] : in_stages_)
    if (t.producer != producer) return true;
  return false;
}

bool ScanQueue::streams(const ShareClass& c, SteadyClock::time_point now) const {
  return !c.scans.empty() || c.in_stages > 0 ||
         (c.served != SteadyClock::time_point{} && now - c.served < kStreamingWindow);
}

bool ScanQueue::robots_stream(SteadyClock::time_point now) const {
  for (const auto& [key, c] : classes_)
    if (key != kNewProducersClass && streams(c, now)) return true;
  return false;
}

ScanQueue::ShareClass* ScanQueue::next_class(SteadyClock::time_point now) {
  ShareClass* best = nullptr;
  for (auto& [key, c] : classes_) {
    if (c.scans.empty()) continue;
    // Its budget spent while a robot streams: it waits for the refill (pop() looks again).
    if (fair_ && key == kNewProducersClass && robots_stream(now) && !shared_budget_.may_serve(now)) {
      shared_deferrals_++;
      continue;
    }
    if (fair_ && c.in_stages > 0) {  // one scan in the stages while a class that used less streams
      bool behind = false;
      for (const auto& [other_key, other] : classes_)
        behind = behind || (&other != &c && other.used_ms < c.used_ms && streams(other, now));
      if (behind) continue;
    }
    if (!best || c.used_ms < best->used_ms ||
        (c.used_ms == best->used_ms && c.scans.front().arrival < best->scans.front().arrival))
      best = &c;
  }
  return best;
}

size_t ScanQueue::next_in_class(const ShareClass& c) const {
  const auto shared = classes_.find(kNewProducersClass);
  if (!fair_ || shared == classes_.end() || &shared->second != &c || shared_served_producer_ == SIZE_MAX) return 0;
  // Round robin by producer id inside the shared class (from its oldest scan on): the next
  // producer after the one served last, its oldest scan (the deque is in arrival order, so
  // each producer's order is kept). Only scans older than the oldest edit: an edit still
  // leaves before every scan that arrived after it.
  const uint64_t before = edits_.empty() ? UINT64_MAX : edits_.front().arrival;
  size_t best = 0, best_gap = SIZE_MAX;
  for (size_t i = 0; i < c.scans.size() && c.scans[i].arrival < before; ++i) {
    const size_t gap = c.scans[i].producer - shared_served_producer_ - 1;  // wraps: cyclic distance
    if (gap < best_gap) best = i, best_gap = gap;
  }
  return best;
}

void ScanQueue::forget(const QueuedScan& s) {
  bytes_by_producer_[s.producer] -= s.bytes;
  depth_by_producer_[s.producer]--;
  if (s.share_class == kNewProducersClass) new_class_depth_[s.producer]--;
  total_bytes_ -= s.bytes;
  depth_--;
}

std::optional<QueuedScan> ScanQueue::pop() {
  std::unique_lock lock(mutex_);
  ShareClass* c = nullptr;
  for (;;) {
    ready_.wait(lock, [&] { return closed_ || !empty_locked(); });
    if (empty_locked()) return std::nullopt;
    uint64_t oldest_scan = UINT64_MAX;
    for (const auto& [key, other] : classes_)
      if (!other.scans.empty()) oldest_scan = std::min(oldest_scan, other.scans.front().arrival);
    if (!edits_.empty() && edits_.front().arrival < oldest_scan) {  // every scan before it has left
      QueuedScan e = std::move(edits_.front());
      edits_.pop_front();
      return e;
    }
    const auto now = SteadyClock::now();
    if ((c = next_class(now))) break;
    // Every waiting class has its scan in the stages: until one leaves (leave() wakes this)
    // or the others stop streaming.
    ready_.wait_for(lock, std::chrono::milliseconds(50));
  }
  const auto pick = c->scans.begin() + static_cast<std::ptrdiff_t>(next_in_class(*c));
  // Classes whose oldest scan arrived before the one served now lose this turn to their share.
  for (auto& [key, other] : classes_)
    if (&other != c && !other.scans.empty() && other.scans.front().arrival < pick->arrival) other.deferrals++;
  virtual_ms_ = c->used_ms;
  c->in_stages++;
  c->served = SteadyClock::now();
  QueuedScan s = std::move(*pick);
  c->scans.erase(pick);
  if (s.share_class == kNewProducersClass) shared_served_producer_ = s.producer;
  c->bytes -= s.bytes;
  s.passed_over = c->deferrals != s.deferrals_at_push;
  forget(s);
  // Its turn is paid now, as predicted; charge() and leave() settle it with what it took.
  s.predicted = costs_.predict(s.walk_voxels, s.mean_ray_voxels);
  c->used_ms += s.predicted.ms / c->share;
  in_stages_[s.arrival] = InStages{s.share_class, s.producer, s.predicted.ms, 0, s.walk_voxels, s.mean_ray_voxels};
  const auto now = SteadyClock::now();
  s.others_stream = others_stream(s.producer, now);
  if (fair_ && s.share_class == kNewProducersClass && s.others_stream)
    s.shared_refusal = shared_budget_.refusal(s.producer, s.predicted, s.walk_voxels, s.mean_ray_voxels,
                                              costs_.longest_learned_ray_voxels());
  served_by_producer_[s.producer] = now;
  return s;
}

void ScanQueue::charge(uint64_t arrival, double ms) {
  if (!(ms > 0)) return;
  std::lock_guard lock(mutex_);
  auto it = in_stages_.find(arrival);
  if (it == in_stages_.end()) return;  // an edit, or it left
  InStages& t = it->second;
  const double over_before = std::max(0.0, t.spent_ms - t.predicted_ms);
  t.spent_ms += ms;
  if (t.share_class == kNewProducersClass)
    shared_budget_.shared_used(ms);
  else
    shared_budget_.robots_used(ms);
  const double over = std::max(0.0, t.spent_ms - t.predicted_ms);
  if (auto c = classes_.find(t.share_class); c != classes_.end())
    c->second.used_ms += (over - over_before) / c->second.share;
}

void ScanQueue::leave(uint64_t arrival, bool applied) {
  {
    std::lock_guard lock(mutex_);
    auto it = in_stages_.find(arrival);
    if (it == in_stages_.end()) return;  // an edit: it is in no class
    const InStages t = it->second;
    in_stages_.erase(it);
    if (applied) costs_.learn(t.walk_voxels, t.mean_ray_voxels, t.spent_ms);
    if (applied) shared_budget_.scan_done(t.producer, t.spent_ms, t.share_class != kNewProducersClass);
    if (auto c = classes_.find(t.share_class); c != classes_.end()) {
      ShareClass& cls = c->second;
      cls.used_ms -= std::max(0.0, t.predicted_ms - t.spent_ms) / cls.share;  // what it did not use
      if (cls.in_stages > 0) cls.in_stages--;
    }
  }
  ready_.notify_all();
}

std::vector<QueuedScan> ScanQueue::take_all() {
  std::lock_guard lock(mutex_);
  std::vector<QueuedScan> out(std::make_move_iterator(edits_.begin()), std::make_move_iterator(edits_.end()));
  edits_.clear();
  for (auto& [key, c] : classes_) {
    std::move(c.scans.begin(), c.scans.end(), std::back_inserter(out));
    c.scans.clear();
    c.bytes = 0;
  }
  std::sort(out.begin(), out.end(), [](const QueuedScan& a, const QueuedScan& b) { return a.arrival < b.arrival; });
  std::fill(bytes_by_producer_.begin(), bytes_by_producer_.end(), 0);
  std::fill(depth_by_producer_.begin(), depth_by_producer_.end(), 0);
  std::fill(new_class_depth_.begin(), new_class_depth_.end(), 0);
  total_bytes_ = 0;
  depth_ = 0;
  return out;
}

SteadyClock::duration ScanQueue::oldest_age(SteadyClock::time_point now) const {
  std::lock_guard lock(mutex_);
  bool any = !edits_.empty();
  SteadyClock::time_point oldest = any ? edits_.front().received : now;
  for (const auto& [key, c] : classes_)
    if (!c.scans.empty()) {
      oldest = any ? std::min(oldest, c.scans.front().received) : c.scans.front().received;
      any = true;
    }
  return any ? now - oldest : SteadyClock::duration::zero();
}

void ScanQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  ready_.notify_all();
}

size_t ScanQueue::depth() const {
  std::lock_guard lock(mutex_);
  return depth_ + edits_.size();
}

uint64_t ScanQueue::bytes() const {
  std::lock_guard lock(mutex_);
  return total_bytes_;
}

uint64_t ScanQueue::producer_bytes(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producer < bytes_by_producer_.size() ? bytes_by_producer_[producer] : 0;
}

size_t ScanQueue::producer_depth(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producer < depth_by_producer_.size() ? depth_by_producer_[producer] : 0;
}

uint64_t ScanQueue::shared_deferrals() const {
  std::lock_guard lock(mutex_);
  return shared_deferrals_;
}

std::string ScanQueue::policy() const {
  const std::string budget = "per-producer byte budget " + std::to_string(per_producer_budget_ >> 20) + " MiB (total " +
                             std::to_string(total_budget_ >> 20) +
                             " MiB); when full the newest scan is dropped "
                             "(counted as dropped: queue full); queued scans are never evicted; ";
  if (!fair_) return budget + "one FIFO: scans are applied in arrival order";
  return budget + "each producer with history has its share of the stages' time, producers without share one of " +
         std::to_string(shared_class_share_).substr(0, 4) +
         " of a producer's (and one byte budget), each scan charged as predicted when it is served: scans are applied in arrival order per producer, by share across producers; a scan that "
         "waited past the latency bound while others were served in its turn is dropped as 'over its share'" +
         (shared_budget_.bounds().enabled
              ? "; while others stream a scan of a robot id without history predicted past its bound or of unknown "
                "cost is rejected as 'predicted too slow', and while a robot with history streams the shared class "
                "waits once its stage time per second is spent"
              : std::string());
}

}  // namespace ort::daemon
