#include "daemon/queries/query_clients.h"

#include <algorithm>
#include <cctype>

namespace ort::daemon {
namespace {

// A refusal's reason without its numbers: "depth 17 is not in 0..16" -> "depth # is not in #..#".
// Waits that ran out name the robot and the states reached; they count as one reason.
std::string reason_key(QueryClients::Count what, const std::string& error) {
  if (what == QueryClients::Count::kNotReady) return "not ready: the awaited map state came after wait_timeout_ms";
  std::string key;
  for (char c : error.substr(0, 120)) {
    if (!std::isdigit(static_cast<unsigned char>(c)))
      key += c;
    else if (key.empty() || key.back() != '#')
      key += '#';
  }
  return key;
}

}  // namespace

QueryClients::QueryClients(size_t per_client_queue, size_t max_clients, int64_t idle_expiry_us)
    : per_client_queue_(per_client_queue), max_clients_(max_clients), idle_expiry_us_(idle_expiry_us) {}

namespace {
// Entries that are no client of their own: no usable address, past the limit, expired.
bool special(const std::string& id) { return id == "?" || id == "*" || id == "~"; }
}  // namespace

size_t QueryClients::named_clients() const {
  size_t n = clients_.size();
  for (const char* s : {"?", "*", "~"}) n -= clients_.count(s);
  return n;
}

void QueryClients::expire_idle(int64_t now_us) {
  auto oldest = clients_.end();
  for (auto it = clients_.begin(); it != clients_.end(); ++it)
    if (!special(it->first) && it->second.queue.empty() && now_us - it->second.stats.last_utime >= idle_expiry_us_ &&
        (oldest == clients_.end() || it->second.stats.last_utime < oldest->second.stats.last_utime))
      oldest = it;
  if (oldest == clients_.end()) return;
  QueryClientStats& f = clients_["~"].stats;
  const QueryClientStats& o = oldest->second.stats;
  f.client_id = "~";
  f.received += o.received, f.answered += o.answered, f.cut += o.cut, f.bad += o.bad, f.busy += o.busy;
  f.not_ready += o.not_ready, f.dropped += o.dropped, f.edits_applied += o.edits_applied;
  f.edits_refused += o.edits_refused;
  f.last_utime = std::max(f.last_utime, o.last_utime);
  clients_.erase(oldest);
}

QueryClients::Client& QueryClients::at(const std::string& client) {
  auto it = clients_.find(client);
  if (it != clients_.end()) return it->second;
  // Past max_clients every new id shares one entry, "*", so the map stays bounded.
  const std::string key = named_clients() >= max_clients_ && !special(client) ? "*" : client;
  Client& c = clients_[key];
  c.stats.client_id = key;
  return c;
}

bool QueryClients::push(const std::string& client, PendingQuery&& q) {
  std::lock_guard lock(mutex_);
  Client& c = at(client);
  if (c.queue.size() >= per_client_queue_) {
    bump(c.stats, Count::kBusy, "busy: the client's queue is full (--query-queue)");
    return false;
  }
  c.queue.push_back(std::move(q));
  ++queued_;
  return true;
}

std::optional<PendingQuery> QueryClients::pop(uint64_t state) {
  std::lock_guard lock(mutex_);
  if (queued_ == 0) return std::nullopt;
  auto it = clients_.upper_bound(next_);
  for (size_t n = 0; n <= clients_.size(); ++n, ++it) {
    if (it == clients_.end()) it = clients_.begin();
    if (!it->second.queue.empty() && it->second.newest_state <= state) {
      PendingQuery q = std::move(it->second.queue.front());
      it->second.queue.pop_front();
      --queued_;
      next_ = it->first;
      return q;
    }
  }
  return std::nullopt;
}

void QueryClients::answered_at(const std::string& client, uint64_t state) {
  std::lock_guard lock(mutex_);
  Client& c = at(client);
  c.newest_state = std::max(c.newest_state, state);
}

uint64_t QueryClients::newest_answered(const std::string& client) {
  std::lock_guard lock(mutex_);
  return at(client).newest_state;
}

uint64_t QueryClients::oldest_answered_queued() const {
  std::lock_guard lock(mutex_);
  uint64_t oldest = UINT64_MAX;
  for (const auto& [id, c] : clients_)
    if (!c.queue.empty()) oldest = std::min(oldest, c.newest_state);
  return oldest;
}

size_t QueryClients::queued() const {
  std::lock_guard lock(mutex_);
  return queued_;
}

void QueryClients::received(const std::string& client, const std::string& reply_channel, int64_t utime) {
  std::lock_guard lock(mutex_);
  if (!clients_.count(client) && named_clients() >= max_clients_) expire_idle(utime);
  QueryClientStats& s = at(client).stats;
  s.received++;
  s.reply_channel = reply_channel;
  s.last_utime = utime;
}

void QueryClients::count(const std::string& client, Count what, const std::string& error) {
  std::lock_guard lock(mutex_);
  bump(at(client).stats, what, error);
}

void QueryClients::bump(QueryClientStats& s, Count what, const std::string& error) {
  switch (what) {
    case Count::kAnswered: s.answered++; break;
    case Count::kAnsweredCut: s.answered++, s.cut++; break;
    case Count::kBad: s.bad++; break;
    case Count::kBusy: s.busy++; break;
    case Count::kNotReady: s.not_ready++; break;
    case Count::kDropped: s.dropped++; break;
    case Count::kEditApplied: s.edits_applied++; break;
    case Count::kEditRefused: s.edits_refused++; break;
  }
  if (error.empty() || what == Count::kAnswered || what == Count::kEditApplied) return;
  s.last_error = error;
  std::string key = reason_key(what, error);
  if (!reasons_.count(key) && reasons_.size() >= kMaxReasons) key = "other";
  reasons_[key]++;
}

std::vector<QueryClientStats> QueryClients::snapshot() const {
  std::lock_guard lock(mutex_);
  std::vector<QueryClientStats> out;
  for (const auto& [name, c] : clients_) {
    out.push_back(c.stats);
    out.back().queue_depth = static_cast<int64_t>(c.queue.size());
  }
  return out;
}

std::vector<std::pair<std::string, int64_t>> QueryClients::refusal_reasons() const {
  std::lock_guard lock(mutex_);
  return {reasons_.begin(), reasons_.end()};
}

void print_query_summary(std::ostream& out, const std::vector<QueryClientStats>& clients) {
  if (clients.empty()) return;
  out << "  queries (per client: received = answered + bad + busy + not ready; dropped: no usable reply address):\n";
  for (const QueryClientStats& c : clients) {
    out << "    " << c.client_id << ": received " << c.received << ", answered " << c.answered << ", bad " << c.bad
        << ", busy " << c.busy << ", not ready " << c.not_ready << ", dropped " << c.dropped;
    if (c.cut) out << ", cut " << c.cut;
    if (c.edits_applied || c.edits_refused)
      out << ", edits applied " << c.edits_applied << " refused " << c.edits_refused;
    if (!c.last_error.empty()) out << " (last: " << c.last_error << ")";
    out << "\n";
  }
}

}  // namespace ort::daemon
