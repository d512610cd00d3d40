#include "daemon/map/map_lock_holders.h"

#include <algorithm>
#include <cstring>

namespace ort::daemon {

void MapLockHolders::note(const char* name, double held_ms) {
  last_.store(name, std::memory_order_relaxed);
  std::lock_guard lock(mutex_);
  auto it = std::find_if(by_name_.begin(), by_name_.end(),
                         [&](const LockHolderFigures& f) { return f.name == name || std::strcmp(f.name, name) == 0; });
  if (it == by_name_.end()) {
    if (by_name_.size() >= kMaxNames) return;  // a bounded table: further names are not kept
    it = by_name_.insert(by_name_.end(), LockHolderFigures{name});
  }
  it->holds++;
  it->max_ms = std::max(it->max_ms, held_ms);
  it->total_ms += held_ms;
}

std::vector<LockHolderFigures> MapLockHolders::figures() const {
  std::vector<LockHolderFigures> out;
  {
    std::lock_guard lock(mutex_);
    out = by_name_;
  }
  std::sort(out.begin(), out.end(),
            [](const LockHolderFigures& a, const LockHolderFigures& b) { return a.max_ms > b.max_ms; });
  return out;
}

}  // namespace ort::daemon
