#include "daemon/queries/edit_gate.h"

#include <cstdio>

#include "protocol/edit_mac.h"

namespace ort::daemon {

EditGate::EditGate(EditGateConfig cfg) : cfg_(std::move(cfg)) {}

void EditGate::forget_before(int64_t utime) {
  while (!by_utime_.empty() && by_utime_.begin()->first < utime) {
    nonces_.erase(by_utime_.begin()->second);
    by_utime_.erase(by_utime_.begin());
  }
}

EditAdmission EditGate::admit(const octomap_rt::map_edit_t& edit, std::string_view channel, int64_t now_utime) {
  EditAdmission a;
  if (cfg_.token.empty()) {
    a.refusal = EditGateRefusal::kEditsOff;
    a.why = "map edits are off: the server was started without --control-token";
    return a;
  }
  if (!protocol::edit_mac_matches(cfg_.token, channel, edit)) {
    a.refusal = EditGateRefusal::kBadMac;
    a.why = "bad MAC: the edit is not signed with the server's control token";
    return a;
  }
  forget_before(now_utime - cfg_.window_us);
  // In double: a utime near INT64_MIN or MAX must not overflow the difference.
  const double off_s = (double(edit.utime) - double(now_utime)) * 1e-6;
  if (!(off_s <= cfg_.window_us * 1e-6 && off_s >= -cfg_.window_us * 1e-6)) {
    char b[160];
    std::snprintf(b, sizeof b, "stale: utime is %.0f s %s the server's clock (window %.0f s)",
                  off_s < 0 ? -off_s : off_s, off_s < 0 ? "behind" : "ahead of", cfg_.window_us * 1e-6);
    a.refusal = EditGateRefusal::kStale;
    a.why = b;
    return a;
  }
  if (nonces_.count(edit.nonce)) {
    a.refusal = EditGateRefusal::kReplayed;
    a.why = "replayed: an edit with this nonce was admitted within the window";
    return a;
  }
  if (nonces_.size() >= cfg_.max_nonces) {
    a.refusal = EditGateRefusal::kTooMany;
    a.why = "too many edits: " + std::to_string(cfg_.max_nonces) + " within the replay window; retry later";
    return a;
  }
  nonces_.insert(edit.nonce);
  by_utime_.emplace(edit.utime, edit.nonce);
  return a;
}

}  // namespace ort::daemon
