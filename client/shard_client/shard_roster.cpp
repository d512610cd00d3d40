#include "shard_client/shard_roster.h"

#include <poll.h>

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "core/clock.h"
#include "protocol/channels.h"
#include "protocol/shards/shard_wire.h"

namespace ort::client {

void ShardRoster::take(const void* data, size_t size, int64_t received_utime) {
  octomap_rt::server_status_t s;
  bool ok = false;
  try {
    ok = s.decode(data, 0, static_cast<int>(size)) >= 0;
  } catch (const std::exception&) {}
  if (!ok) return refuse("undecodable");
  protocol::ShardSet heard;
  if (const auto fault = protocol::read_shard_set(s, heard); fault != protocol::ShardFieldFault::kNone)
    return refuse(protocol::to_string(fault));
  if (!(s.resolution > 0 && s.resolution < 1e6)) return refuse("bad resolution");
  if (set_ && (!protocol::same_shard_set(*set_, heard) || s.resolution != resolution()))
    return refuse("another shard set");
  if (!set_) set_ = heard;
  members_[heard.index] = Member{std::move(s), received_utime};
}

double ShardRoster::resolution() const { return members_.empty() ? 0 : members_.begin()->second.status.resolution; }

std::vector<uint32_t> ShardRoster::missing() const {
  std::vector<uint32_t> out;
  if (!set_) return out;
  for (uint32_t i = 0; i < set_->count; ++i)
    if (!members_.count(i)) out.push_back(i);
  return out;
}

std::vector<uint32_t> ShardRoster::late(int64_t now_utime, double late_after_s) const {
  std::vector<uint32_t> out;
  for (const auto& [i, m] : members_)
    if (double(now_utime - m.received_utime) > late_after_s * 1e6) out.push_back(i);
  return out;
}

std::string ShardRoster::shortfall(int64_t now_utime, double late_after_s) const {
  if (!set_) return "no shard heard";
  std::string out;
  auto add = [&](const std::string& s) { out += (out.empty() ? "" : "; ") + s; };
  for (uint32_t i : missing()) add("shard " + std::to_string(i) + " of " + std::to_string(set_->count) + " not heard");
  for (uint32_t i : late(now_utime, late_after_s)) {
    char age[64];
    std::snprintf(age, sizeof age, "%.1f", double(now_utime - members_.at(i).received_utime) / 1e6);
    add("shard " + std::to_string(i) + " late (last status " + age + " s ago)");
  }
  return out;
}

ShardRoster discover_shards(const std::string& url, const std::string& ns, double timeout_s) {
  lcm::LCM lc(url);
  if (!lc.good()) throw std::runtime_error("LCM cannot start on " + url);
  ShardRoster roster;
  struct Sink {
    ShardRoster* r;
    void on(const lcm::ReceiveBuffer* rb, const std::string&) { r->take(rb->data, rb->data_size, now_utime()); }
  } sink{&roster};
  lc.subscribe(protocol::channels_in(ns).status, &Sink::on, &sink);
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(timeout_s);
  while (!roster.complete()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now());
    if (left.count() <= 0) break;
    pollfd p{lc.getFileno(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(std::min<int64_t>(left.count(), 100))) > 0) lc.handleTimeout(0);
  }
  return roster;
}

}  // namespace ort::client
