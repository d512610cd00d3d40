#include "daemon/map/change_journal.h"

#include <algorithm>
#include <utility>

#include "core/clock.h"

namespace ort::daemon {

ChangeJournal::ChangeJournal(size_t max_changes, size_t max_states)
    : max_changes_(max_changes), max_states_(std::max<size_t>(1, max_states)) {}

void ChangeJournal::applied(const LeafChanges& changes, float occupancy_thres_log, uint64_t version) {
  if (!armed()) return;
  const auto t0 = SteadyClock::now();
  State s;
  s.version = version;
  // Classified here, outside the journal's lock: stage 2's time, one pass over the log.
  changes.for_each([&](const LeafChange& c) {
    const bool occ = c.after >= occupancy_thres_log;
    if (c.was_unknown() || (c.before >= occupancy_thres_log) != occ)
      s.changes.push_back(ClassChange{c.morton() | (occ ? ClassChange::kOccupiedBit : 0)});
  });
  std::lock_guard lock(mutex_);
  stats_.scans++;
  stats_.changes += s.changes.size();
  held_ += s.changes.size();
  states_.push_back(std::move(s));
  while (states_.size() > 1 && (held_ > max_changes_ || states_.size() > max_states_)) {
    held_ -= states_.front().changes.size();
    states_.pop_front();
    stats_.trimmed++;
  }
  stats_.record_ms += ms_since(t0);
}

bool ChangeJournal::changes_between(uint64_t from, uint64_t to, size_t max_out, std::vector<ClassChange>& out) {
  std::lock_guard lock(mutex_);
  if (to == from) return ++stats_.answered, true;
  auto refuse = [&] { return ++stats_.refused, false; };
  if (to < from) return refuse();
  // The states are appended in version order; find from + 1 and require every version up to `to`.
  auto it = std::lower_bound(states_.begin(), states_.end(), from + 1,
                             [](const State& s, uint64_t v) { return s.version < v; });
  size_t n = 0;
  uint64_t want = from + 1;
  for (auto i = it; want <= to; ++i, ++want) {
    if (i == states_.end() || i->version != want) return refuse();
    n += i->changes.size();
    if (n > max_out) return refuse();
  }
  out.reserve(out.size() + n);
  for (auto i = it; i != states_.end() && i->version <= to; ++i)
    out.insert(out.end(), i->changes.begin(), i->changes.end());
  ++stats_.answered;
  return true;
}

ChangeJournalStats ChangeJournal::stats() const {
  std::lock_guard lock(mutex_);
  ChangeJournalStats s = stats_;
  s.held_changes = held_;
  return s;
}

}  // namespace ort::daemon
