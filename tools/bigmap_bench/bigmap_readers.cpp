#include "bigmap_readers.h"

#include <algorithm>
#include <random>

#include "core/clock.h"
#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_request_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "protocol/channels.h"

namespace ort::bench {
namespace {

// A map request's reply channel must carry the protocol's prefix (else it is refused unanswered).
const std::string kMapReply = std::string(ort::protocol::kMapReplyPrefix) + "BENCH";
constexpr const char* kQueryReply = "BENCH_QUERY_REPLY";

double seconds_between(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

BenchReaders::BenchReaders(daemon::MappingServer& server, lcm::LCM& lc, double snapshot_period_s, double query_rate_hz,
                           int query_clients, const double box_min[3], const double box_max[3])
    : server_(server),
      lc_(lc),
      snapshot_period_s_(snapshot_period_s),
      query_rate_hz_(query_rate_hz),
      query_clients_(std::max(1, query_clients)) {
  std::copy(box_min, box_min + 3, box_min_);
  std::copy(box_max, box_max + 3, box_max_);
  server_.lcm_loop().subscribe(kMapReply, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    octomap_rt::map_chunk_t c;
    if (c.decode(rb.data, 0, static_cast<int>(rb.data_size)) < 0) return;
    std::lock_guard lock(mutex_);
    if (c.request_id != chunk_request_) return;
    chunks_expected_ = c.num_chunks;
    chunks_got_++;
    if (c.num_chunks == 0) stats_.snapshot_error = c.error;  // a refusal (busy, bad request)
    stats_.snapshot_bytes += c.data_size;
  });
  server_.lcm_loop().subscribe(kQueryReply, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    octomap_rt::occupancy_reply_t r;
    if (r.decode(rb.data, 0, static_cast<int>(rb.data_size)) < 0) return;
    const auto now = SteadyClock::now();
    std::lock_guard lock(mutex_);
    auto it =
        std::find_if(in_flight_.begin(), in_flight_.end(), [&](const auto& q) { return q.first == r.request_id; });
    if (it == in_flight_.end()) return;
    if (r.status == octomap_rt::occupancy_reply_t::REPLY_OK)
      stats_.query_ms.push_back(1e3 * seconds_between(it->second, now));
    else
      stats_.queries_not_ok++;
    in_flight_.erase(it);
  });
}

BenchReaders::~BenchReaders() { stop(); }

void BenchReaders::start() {
  if (snapshot_period_s_ > 0) snapshots_ = std::thread([this] { pull_snapshots(); });
  if (query_rate_hz_ > 0)
    for (int c = 0; c < query_clients_; ++c) queries_.emplace_back([this, c] { send_queries(c); });
}

void BenchReaders::stop() {
  stop_ = true;
  if (snapshots_.joinable()) snapshots_.join();
  for (auto& q : queries_)
    if (q.joinable()) q.join();
  queries_.clear();
}

ReaderStats BenchReaders::stats() {
  std::lock_guard lock(mutex_);
  ReaderStats s = stats_;
  s.queries_unanswered = static_cast<int64_t>(in_flight_.size());
  return s;
}

// One fresh snapshot at a time; the next is asked for a period after the last was asked for
// (or at once, when fetching took longer).
void BenchReaders::pull_snapshots() {
  int64_t id = 0;
  while (!stop_) {
    const auto t0 = SteadyClock::now();
    octomap_rt::map_request_t r{};
    r.request_id = ++id;
    r.snapshot_id = -1;
    r.format = octomap_rt::map_chunk_t::FORMAT_OCTOMAP_FULL;
    r.client_id = "bench";
    r.reply_channel = kMapReply;
    {
      std::lock_guard lock(mutex_);
      chunk_request_ = id;
      chunks_expected_ = -1;
      chunks_got_ = 0;
    }
    lc_.publish(ort::protocol::kMapRequestChannel, &r);
    bool done = false;
    while (!stop_ && !done && seconds_between(t0, SteadyClock::now()) < 120) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      std::lock_guard lock(mutex_);
      done = chunks_expected_ > 0 && chunks_got_ >= chunks_expected_;
      if (chunks_expected_ == 0) break;  // refused: counted below, asked again next period
    }
    const double s = seconds_between(t0, SteadyClock::now());
    {
      std::lock_guard lock(mutex_);
      if (done) {
        stats_.snapshots++;
        stats_.snapshot_s_sum += s;
        stats_.snapshot_s_max = std::max(stats_.snapshot_s_max, s);
      } else if (!stop_) {
        stats_.snapshot_timeouts++;
      }
    }
    while (!stop_ && seconds_between(t0, SteadyClock::now()) < snapshot_period_s_)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// One query client: point queries of 64 random points in the map's box, at its share of the
// rate (no waiting for scans). The clients start spread over one period so their queries interleave.
void BenchReaders::send_queries(int client) {
  std::mt19937 rng(7 + static_cast<unsigned>(client));
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const auto period = std::chrono::duration<double>(query_clients_ / query_rate_hz_);
  auto next = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(period * client / query_clients_);
  std::this_thread::sleep_until(next);
  // Client 0 keeps the one-client name of earlier runs.
  const std::string client_id = client == 0 ? "bench-queries" : "bench-queries-" + std::to_string(client);
  while (!stop_) {
    octomap_rt::occupancy_query_t q{};
    const int64_t id = ++next_query_id_;
    q.request_id = id;
    q.wait_seq = -1;
    q.client_id = client_id;
    q.reply_channel = kQueryReply;
    for (int i = 0; i < 64; ++i)
      for (int k = 0; k < 3; ++k)
        q.xyz.push_back(static_cast<float>(box_min_[k] + u(rng) * (box_max_[k] - box_min_[k])));
    q.num_xyz = static_cast<int32_t>(q.xyz.size());
    {
      std::lock_guard lock(mutex_);
      in_flight_.emplace_back(id, SteadyClock::now());
      stats_.queries_sent++;
    }
    lc_.publish(ort::protocol::kQueryChannel, &q);
    next += std::chrono::duration_cast<SteadyClock::duration>(period);
    std::this_thread::sleep_until(next);
  }
}

}  // namespace ort::bench
