#include "daemon/queries/edit_audit.h"

#include <cstdio>

#include "octomap_rt/occupancy_reply_t.hpp"

namespace ort::daemon {
namespace {

using Edit = octomap_rt::map_edit_t;
using Reply = octomap_rt::occupancy_reply_t;

std::string what(const Edit& e) {
  switch (e.op) {
    case Edit::OP_CLEAR_TO_FREE:
      return e.flags & Edit::FLAG_INCLUDE_UNKNOWN ? "clear-box to free (unknown voxels too)"
                                                  : "clear-box to free (known voxels only)";
    case Edit::OP_CLEAR_TO_UNKNOWN: return "clear-box to unknown";
    case Edit::OP_RESET: return "reset";
  }
  return "op " + std::to_string(e.op);
}

std::string box(const Edit& e) {
  char b[256];
  std::snprintf(b, sizeof b, " [%g, %g, %g]..[%g, %g, %g] m", e.box_min[0], e.box_min[1], e.box_min[2], e.box_max[0],
                e.box_max[1], e.box_max[2]);
  return b;
}

const char* status_name(int8_t status) {
  switch (status) {
    case Reply::REPLY_OK: return "OK";
    case Reply::REPLY_BAD_REQUEST: return "BAD_REQUEST";
    case Reply::REPLY_BUSY: return "BUSY";
    case Reply::REPLY_NOT_READY: return "NOT_READY";
    case Reply::REPLY_REFUSED: return "REFUSED";
  }
  return "?";
}

}  // namespace

std::string edit_audit_line(const Edit& edit, const MapEditResult& result, int8_t status, const std::string& error) {
  std::string line = "octomap-rt-server: map edit " + std::to_string(edit.request_id) + " from client '" +
                     edit.client_id + "' (reply " + edit.reply_channel + "): " + what(edit);
  if (edit.op != Edit::OP_RESET) line += box(edit);
  if (status == Reply::REPLY_OK) {
    char b[160];
    std::snprintf(b, sizeof b, ": applied, map state %llu, %lld voxels in the box, %.1f ms under the map lock",
                  static_cast<unsigned long long>(result.version), static_cast<long long>(result.voxels),
                  result.locked_ms);
    return line + b;
  }
  return line + ": refused (" + status_name(status) + "): " + error;
}

void EditAudit::record(const Edit& edit, const MapEditResult& result, int8_t status, const std::string& error,
                       bool proven) {
  const std::string line = edit_audit_line(edit, result, status, error);
  std::lock_guard lock(mutex_);
  if (!proven) {
    const auto now = SteadyClock::now();
    if (now - period_start_ >= kUnprovenPeriod) {
      if (unproven_in_period_ > kUnprovenLines)
        log_.warning("octomap-rt-server: " + std::to_string(unproven_in_period_ - kUnprovenLines) +
                     " more map edits without the control token refused and not logged (counted in the status)");
      period_start_ = now;
      unproven_in_period_ = 0;
    }
    if (++unproven_in_period_ > kUnprovenLines) return;
  }
  log_.info(line);
}

}  // namespace ort::daemon
