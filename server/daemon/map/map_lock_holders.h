// Who holds a map's lock, and for how long. Each holder of the map of record's lock names
// itself for the time it holds it (MapHoldNote): per name, the holds, the longest and their
// total, and which holder let go of the lock last. Stage 2 reads that name after it waited for
// the lock (daemon/pipeline/scan_pipeline.cpp): the holder it waited for at the end, named
// beside the longest wait (the bench's "stall", docs/BENCHMARKS.md).
//
// Usage: MapHoldNote right after the lock it notes (it ends just before the lock is let go).
// Names are string literals (kept by pointer). Thread-safe.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "core/clock.h"

namespace ort::daemon {

struct LockHolderFigures {
  const char* name = "";
  uint64_t holds = 0;
  double max_ms = 0, total_ms = 0;
};

class MapLockHolders {
 public:
  // At the end of a hold of `held_ms`.
  void note(const char* name, double held_ms);
  // The holder that let go of the lock last ("" before any).
  const char* last_released() const { return last_.load(std::memory_order_relaxed); }
  // Per holder, the longest hold first.
  std::vector<LockHolderFigures> figures() const;

 private:
  static constexpr size_t kMaxNames = 32;  // the daemon's holders are a dozen
  mutable std::mutex mutex_;
  std::vector<LockHolderFigures> by_name_;
  std::atomic<const char*> last_{""};
};

class MapHoldNote {
 public:
  MapHoldNote(MapLockHolders& holders, const char* name) : holders_(holders), name_(name), start_(SteadyClock::now()) {}
  ~MapHoldNote() { holders_.note(name_, ms_since(start_)); }
  MapHoldNote(const MapHoldNote&) = delete;
  MapHoldNote& operator=(const MapHoldNote&) = delete;

 private:
  MapLockHolders& holders_;
  const char* name_;
  SteadyClock::time_point start_;
};

}  // namespace ort::daemon
