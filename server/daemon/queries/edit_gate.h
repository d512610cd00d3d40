// Which map edits the server lets through to the map: those signed with its control token
// (protocol/edit_mac.h), sent within its time window, with a nonce it has not seen. The nonces
// of admitted edits are kept until their utime leaves the window (an edit that old is refused as
// stale anyway), at most max_nonces of them: past that, edits are refused as too many until old
// ones expire, so the cache's memory is bounded whatever the senders do. Only edits with a good
// MAC reach the cache: without the token nobody can fill it.
//
// Runs on the LCM thread (QueryService::on_edit); not thread-safe.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>

#include "octomap_rt/map_edit_t.hpp"

namespace ort::daemon {

struct EditGateConfig {
  std::string token;               // "": every edit is refused
  int64_t window_us = 30'000'000;  // |utime - the server's clock| at most this
  size_t max_nonces = 4096;        // admitted edits remembered within the window
};

enum class EditGateRefusal { kNone, kEditsOff, kBadMac, kStale, kReplayed, kTooMany };

struct EditAdmission {
  EditGateRefusal refusal = EditGateRefusal::kNone;
  std::string why;  // the ack's error
  bool admitted() const { return refusal == EditGateRefusal::kNone; }
  // The sender holds the token: a fresh edit with a good MAC (a replayed or stale one proves
  // nothing, since anyone who saw it can send it again; its audit line is rate-limited).
  bool authenticated() const { return refusal == EditGateRefusal::kNone || refusal == EditGateRefusal::kTooMany; }
};

class EditGate {
 public:
  explicit EditGate(EditGateConfig cfg);
  // `channel`: the channel the edit arrived on (part of its MAC); now_utime: the server's clock.
  EditAdmission admit(const octomap_rt::map_edit_t& edit, std::string_view channel, int64_t now_utime);
  size_t remembered() const { return nonces_.size(); }

 private:
  void forget_before(int64_t utime);

  EditGateConfig cfg_;
  std::set<std::pair<int64_t, int64_t>> by_utime_;  // (utime, nonce) of admitted edits
  std::unordered_set<int64_t> nonces_;
};

}  // namespace ort::daemon
