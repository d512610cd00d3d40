// The audit line of a map edit, written to the daemon's log for every edit that named a usable
// client: who (client id, reply channel), what (op, flags), the box as sent, and the result
// (applied at which map state, or refused and why), so an operator can tell who changed the map.
//
// Edits refused without proof of the control token (edits off, bad MAC, replayed, stale) are
// logged at most kUnprovenLines per kUnprovenPeriod, then one line says how many more were
// refused: anyone on the network can send them, and the log must not grow at their rate (the
// status counts every one of them, per client and reason).
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "core/clock.h"
#include "core/log.h"

#include "daemon/map/map_edit_item.h"
#include "octomap_rt/map_edit_t.hpp"

namespace ort::daemon {

std::string edit_audit_line(const octomap_rt::map_edit_t& edit, const MapEditResult& result, int8_t status,
                            const std::string& error);

// Called from the LCM thread (refusals) and stage 2 (results): one line at a time.
class EditAudit {
 public:
  static constexpr int kUnprovenLines = 10;
  static constexpr std::chrono::seconds kUnprovenPeriod{10};

  explicit EditAudit(Log log) : log_(std::move(log)) {}
  // `proven`: the edit showed the control token (every authenticated edit is logged).
  void record(const octomap_rt::map_edit_t& edit, const MapEditResult& result, int8_t status, const std::string& error,
              bool proven);

 private:
  Log log_;
  std::mutex mutex_;
  SteadyClock::time_point period_start_{};
  int64_t unproven_in_period_ = 0;
};

}  // namespace ort::daemon
