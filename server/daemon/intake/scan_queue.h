// The queue between the LCM thread and stage 1, with a byte budget PER PRODUCER (one
// flooding robot cannot starve the others of memory) and a total budget.
//
// Share of the stages (docs/RELIABILITY.md, "Bounded cost"): scans wait in one queue per
// share class, and the stages serve the class that has used the least of their time
// (start-time fair queuing on stage time). A scan's time is charged to its class when it is
// served, as predicted (intake/stage_cost_model.h: its walk times what a voxel of that shape
// took before), so that a class's turn is spent before its scan runs, not seconds later
// when a stage finishes it; the pipeline's measured shoot and apply times then settle it
// (what passes the prediction is charged as it is measured, what it did not use is given
// back when the scan leaves). A class's time counts divided by its share: 1 for a
// producer with history, shared_class_share (less) for the shared class. A producer with history (ScanCostBounds' share_history_*) is a
// class of its own; every producer without (a robot id never seen, or seen only briefly) is
// in ONE class together, so fresh ids cost nothing to make but share one turn. While a known
// robot streams, one class, however expensive its scans, takes at most its share of the
// stages' time; what it sends beyond waits, and a scan that waited past the latency bound
// while other classes were served in its turn is dropped as "over its share". A class that
// was idle comes back at the others' level (no saved credit). And while a class that used
// less streams (has scans waiting or in the stages, or had one served within
// kStreamingWindow), a class has at most one scan in the stages: a scan is applied whole, so
// what a robot's scan may wait for is one scan of each class ahead of it, not one in each
// stage. fair = false: one FIFO. On top of the share, the shared class's budget
// (intake/shared_class_budget.h): its scans' cost is bounded one by one while others stream
// (pop() sets shared_refusal; stage 1 refuses them), and its stage time per second while a
// robot with history streams (next_class() holds it back while that is spent): a scan is
// applied whole, and a work-conserving share hands an idle robot's time to the far scans.
//
// Order: each producer's scans leave in its arrival order (a producer that earns its history
// takes its scans waiting in the shared class into its own, in order); across producers, by share;
// inside the shared class, round robin by producer id (a new robot's first scans wait for one
// scan of each other fresh id, not for every far scan queued before them). A map edit
// leaves only after every scan that arrived before it, and before any that arrived after.
//
// Policy when a producer's budget is full: the NEWEST scan is refused (the caller counts it
// as dropped: queue full). The producers without history are held to one producer's budget
// together. Older queued scans are never evicted.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/clock.h"
#include "daemon/intake/shared_class_budget.h"
#include "daemon/intake/stage_cost_model.h"
#include "octomap_rt/scan_t.hpp"

namespace ort::daemon {

// A map edit rides the queue to keep its place among the scans; what it is and how it is
// applied are the map's (daemon/map/map_edit_item.h): the queue only holds it.
struct MapEditItem;

// The share class of every producer without history.
inline constexpr size_t kNewProducersClass = SIZE_MAX;
// A class served this recently still streams (a robot at 1 Hz or faster).
inline constexpr std::chrono::seconds kStreamingWindow{2};
// The shared class's share of the stages, against 1 for each producer with history: fresh
// ids are free to make, so together they get less than one robot.
inline constexpr double kSharedClassShare = 0.25;

struct QueuedScan {
  size_t producer = 0;
  bool established = false;          // set by the intake: the producer has history (its own class)
  uint64_t arrival = 0;              // global arrival number, set by the queue
  size_t share_class = 0;            // set by the queue: whose turn it waits for
  uint64_t deferrals_at_push = 0;    // set by the queue: its class's deferrals when it arrived
  bool passed_over = false;          // set by pop(): other classes were served in its class's turn
  bool others_stream = false;        // set by pop(): another producer's scans wait, are in the stages,
                                     // or one was served within kStreamingWindow
  SteadyClock::time_point received;  // when the LCM thread got it
  SteadyClock::time_point decoded;   // when the LCM thread had decoded and checked it (unset: = received)
  size_t bytes = 0;                  // what it holds against the budget
  double walk_voxels = 0;            // set by the intake: its rays' voxels (rays x mean length)
  double mean_ray_voxels = 0;        // set by the intake
  StageCostPrediction predicted;     // set by pop(): what it will cost the stages
  // Set by pop() for a scan of the shared class while others stream: why it is refused for its
  // cost (intake/shared_class_budget.h); empty: admitted.
  std::string shared_refusal;
  octomap_rt::scan_t msg;
  std::shared_ptr<MapEditItem> edit;  // set: a map edit, not a scan (msg is empty)
};

// Memory a queued scan holds (its points dominate).
size_t queued_bytes(const octomap_rt::scan_t& msg);

class ScanQueue {
 public:
  ScanQueue(uint64_t per_producer_budget, uint64_t total_budget, bool fair = true,
            double shared_class_share = kSharedClassShare, SharedClassBounds shared_bounds = SharedClassBounds::off());

  // False when the producer's (or the total) budget would be exceeded, or after close().
  bool try_push(QueuedScan&& s);
  // Queues a map edit in arrival order with the scans, outside every byte budget (edits are
  // small and rate-limited by the query service). False after close().
  bool push_edit(std::shared_ptr<MapEditItem> edit);
  // Blocks until a scan may be served; nullopt once closed and empty.
  std::optional<QueuedScan> pop();
  // What the scan pop() returned as `arrival` took of a stage (the pipeline's measured time).
  void charge(uint64_t arrival, double ms);
  // A scan pop() returned has left the stages, once for each: `applied` when both stages ran
  // it whole (its time then teaches the cost model), false when it was refused or dropped.
  void leave(uint64_t arrival, bool applied);
  void leave(const QueuedScan& s) { leave(s.arrival, false); }
  // No more pushes; pop() drains what is left, then returns nullopt.
  void close();
  // Removes and returns every queued scan (the drain deadline passed: the caller counts
  // them as dropped). pop() then returns nullopt once closed.
  std::vector<QueuedScan> take_all();
  // How long the oldest queued scan has waited (zero when empty).
  SteadyClock::duration oldest_age(SteadyClock::time_point now = SteadyClock::now()) const;
  uint64_t total_budget() const { return total_budget_; }

  size_t depth() const;
  uint64_t bytes() const;
  uint64_t producer_bytes(size_t producer) const;
  size_t producer_depth(size_t producer) const;
  uint64_t per_producer_budget() const { return per_producer_budget_; }
  std::string policy() const;
  // Times the shared class was not served because its stage-time budget was spent while a
  // robot with history streamed (its scans waited; intake/shared_class_budget.h).
  uint64_t shared_deferrals() const;

 private:
  struct ShareClass {
    std::deque<QueuedScan> scans;  // arrival order
    double used_ms = 0;            // stage time served so far (its start tag while waiting)
    uint64_t deferrals = 0;        // times another class was served while this one waited
    uint64_t bytes = 0;
    int in_stages = 0;  // popped, not yet left
    SteadyClock::time_point served;
    double share = 1;
  };
  // A scan in the stages: what its class was charged for it so far.
  struct InStages {
    size_t share_class = 0, producer = 0;
    double predicted_ms = 0, spent_ms = 0;
    double walk_voxels = 0, mean_ray_voxels = 0;
  };
  size_t class_for(const QueuedScan& s) const;  // under mutex_
  // A producer that earned its history: its scans waiting in the shared class join its own.
  void move_to_own_class(size_t producer);  // under mutex_
  // The class to serve next (least used; ties: oldest head), or nullptr when no scan may be.
  ShareClass* next_class(SteadyClock::time_point now);  // under mutex_
  ShareClass& class_named(size_t key);                  // under mutex_; made with its share
  size_t next_in_class(const ShareClass& c) const;      // under mutex_: the index of the scan to serve
  bool streams(const ShareClass& c, SteadyClock::time_point now) const;
  bool empty_locked() const;
  bool others_stream(size_t producer, SteadyClock::time_point now) const;
  bool robots_stream(SteadyClock::time_point now) const;  // a class other than the shared one streams
  void forget(const QueuedScan& s);                       // its bytes and depth, once it left the queue

  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::map<size_t, ShareClass> classes_;
  std::deque<QueuedScan> edits_;            // arrival order
  std::map<uint64_t, InStages> in_stages_;  // by arrival
  StageCostModel costs_;
  SharedClassBudget shared_budget_;
  uint64_t shared_deferrals_ = 0;
  std::vector<uint64_t> bytes_by_producer_;
  std::vector<size_t> depth_by_producer_;
  std::vector<size_t> new_class_depth_;                      // by producer: its scans waiting in kNewProducersClass
  std::vector<SteadyClock::time_point> served_by_producer_;  // its last scan's pop()
  size_t depth_ = 0;
  uint64_t total_bytes_ = 0;
  uint64_t next_arrival_ = 0;
  double virtual_ms_ = 0;                     // the used time of the class served last, when it was served
  size_t shared_served_producer_ = SIZE_MAX;  // the producer whose scan the shared class served last
  uint64_t per_producer_budget_, total_budget_;
  bool fair_;
  double shared_class_share_;
  bool closed_ = false;
};

}  // namespace ort::daemon
