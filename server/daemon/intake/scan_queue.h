// The queue between the LCM thread and stage 1: one FIFO, so scans leave in ARRIVAL order
// across producers, with a byte budget PER PRODUCER (one flooding robot cannot starve the
// others of memory) and a total budget.
//
// Policy when a producer's budget is full: the NEWEST scan is refused (the caller counts it
// as dropped: queue full). Older queued scans are never evicted, so what is applied is
// always a prefix-preserving subsequence of the arrival order and nothing reorders.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "core/clock.h"
#include "octomap_rt/scan_t.hpp"

namespace ort::daemon {

// A map edit rides the queue to keep its place among the scans; what it is and how it is
// applied are the map's (daemon/map/map_edit_item.h): the queue only holds it.
struct MapEditItem;

struct QueuedScan {
  size_t producer = 0;
  uint64_t arrival = 0;              // global arrival number, set by the queue
  SteadyClock::time_point received;  // when the LCM thread got it
  SteadyClock::time_point decoded;   // when the LCM thread had decoded and checked it (unset: = received)
  size_t bytes = 0;                  // what it holds against the budget
  octomap_rt::scan_t msg;
  std::shared_ptr<MapEditItem> edit;  // set: a map edit, not a scan (msg is empty)
};

// Memory a queued scan holds (its points dominate).
size_t queued_bytes(const octomap_rt::scan_t& msg);

class ScanQueue {
 public:
  ScanQueue(uint64_t per_producer_budget, uint64_t total_budget);

  // False when the producer's (or the total) budget would be exceeded, or after close().
  bool try_push(QueuedScan&& s);
  // Queues a map edit in arrival order with the scans, outside every byte budget (edits are
  // small and rate-limited by the query service). False after close().
  bool push_edit(std::shared_ptr<MapEditItem> edit);
  // Blocks until a scan is there; nullopt once closed and empty.
  std::optional<QueuedScan> pop();
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

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<QueuedScan> fifo_;
  std::vector<uint64_t> bytes_by_producer_;
  std::vector<size_t> depth_by_producer_;
  uint64_t total_bytes_ = 0;
  uint64_t next_arrival_ = 0;
  uint64_t per_producer_budget_, total_budget_;
  bool closed_ = false;
};

}  // namespace ort::daemon
