#include "load_test.h"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "cli/replay/scan_message.h"
#include "core/clock.h"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"
#include "scene/scan_set.h"
#include "scene/scene_presets.h"
#include "scene/synthetic_scene.h"

namespace ort::cli {
namespace {

bool write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out);
}

int run_command(const std::vector<std::string>& argv) {
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  int st = 0;
  ::waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

pid_t spawn(const std::vector<std::string>& argv, const std::string& log_path) {
  const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write " + log_path + ": " + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    std::fprintf(stderr, "exec %s: %s\n", args[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(fd);
  if (pid < 0) throw std::runtime_error("fork failed");
  return pid;
}

double peak_rss_mib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  return 0;
}

double rss_mib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  return 0;
}

// Scans of at most `points` points (thinned evenly; the synthetic scene's repeated up to it):
// the scene's scans in their order.
std::vector<PosedScan> load_scans(const LoadTestConfig& cfg) {
  ScanSet scene;
  if (cfg.scene == "synthetic") {
    scene = make_synthetic_rooms();
  } else if (is_preset(cfg.scene)) {
    PresetOptions o;
    o.data_dir = cfg.data_dir;
    scene = make_preset(cfg.scene, o);
  } else {
    scene = load_scan_graph(cfg.scene);
  }
  std::vector<PosedScan> out;
  const size_t points = size_t(cfg.points);
  for (const PosedScan& src : scene.scans) {
    PosedScan s;
    s.pose = src.pose;
    if (src.points.size() == 0) continue;
    if (cfg.scene == "synthetic") {
      for (size_t i = 0; i < points; ++i) s.points.push_back(src.points[i % src.points.size()]);
    } else {
      const size_t step = std::max<size_t>(1, (src.points.size() + points - 1) / points);
      for (size_t i = 0; i < src.points.size(); i += step) s.points.push_back(src.points[i]);
    }
    out.push_back(std::move(s));
  }
  if (out.empty()) throw std::runtime_error("the scene " + cfg.scene + " has no scans");
  return out;
}

// Decodes the server's status on its own LCM instance and keeps what the report needs.
class StatusTracker {
 public:
  explicit StatusTracker(const std::string& url) : lcm_(url) {
    lcm_.subscribe(ort::protocol::kStatusChannel, &StatusTracker::on_status, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(100);
    });
  }
  ~StatusTracker() {
    stop_ = true;
    thread_.join();
  }
  octomap_rt::server_status_t latest() {
    std::lock_guard lock(m_);
    return latest_;
  }
  void fill(LoadReport& r) {
    std::lock_guard lock(m_);
    r.e2e_p99_ms_max = max_p99_;
    r.statuses = statuses_;
    r.degraded_statuses = degraded_;
  }

 private:
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const octomap_rt::server_status_t* s) {
    std::lock_guard lock(m_);
    latest_ = *s;
    statuses_++;
    degraded_ += s->state == octomap_rt::server_status_t::STATE_DEGRADED;
    max_p99_ = std::max(max_p99_, double(s->end_to_end_ms_p99));
  }

  lcm::LCM lcm_;
  std::mutex m_;
  octomap_rt::server_status_t latest_{};
  int64_t statuses_ = 0, degraded_ = 0;
  double max_p99_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

void publish_for(const std::string& url, int index, const LoadTestConfig& cfg, const std::vector<PosedScan>& scans,
                 std::atomic<int64_t>& published, std::atomic<int64_t>& errors) {
  lcm::LCM lc(url);
  const std::string robot = "load" + std::to_string(index);
  const std::string channel = scan_channel(ort::protocol::kScanChannelPrefix, robot);
  const auto period =
      std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(1.0 / cfg.rate_hz));
  const auto end = SteadyClock::now() +
                   std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(cfg.duration_s));
  auto next = SteadyClock::now() + period * index / std::max(1, cfg.producers);  // spread the producers over one period
  std::vector<uint8_t> buf;
  for (int64_t seq = 0; next < end; ++seq) {
    std::this_thread::sleep_until(next);
    next += period;
    ScanMessageFields f;
    f.robot_id = robot;
    f.seq = seq;
    f.utime = now_utime();
    const octomap_rt::scan_t msg = make_scan_message(scans[size_t(seq + index) % scans.size()], f);
    buf.resize(size_t(msg.getEncodedSize()));
    msg.encode(buf.data(), 0, int(buf.size()));
    if (lc.publish(channel, buf.data(), unsigned(buf.size())) != 0) errors++;
    published++;
  }
}

void count_totals(const octomap_rt::server_status_t& s, LoadReport& r) {
  r.received = r.applied = r.rejected = r.dropped = r.in_flight = r.missed = 0;
  r.drop_reasons.clear();
  r.reject_reasons.clear();
  for (const auto& rb : s.robots) {
    r.received += rb.scans_received;
    r.applied += rb.scans_applied;
    r.rejected += rb.scans_rejected;
    r.dropped += rb.scans_dropped;
    r.in_flight += rb.queue_depth;
    r.missed += rb.scans_missed;
    for (int i = 0; i < rb.num_drop_reasons; ++i) r.drop_reasons[rb.drop_reason[i]] += rb.drop_count[i];
    for (int i = 0; i < rb.num_reject_reasons; ++i) r.reject_reasons[rb.reject_reason[i]] += rb.reject_count[i];
  }
  r.kernel_drops = s.socket_rcvbuf_drops;
  r.e2e_p99_ms_last = s.end_to_end_ms_p99;
  r.last_message = s.message;
}

}  // namespace

std::string enter_private_network() {
  const uid_t uid = ::geteuid();
  const gid_t gid = ::getegid();
  if (::unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0) return std::string("unshare: ") + std::strerror(errno);
  write_text("/proc/self/setgroups", "deny");
  write_text("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1\n");
  write_text("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1\n");
  if (run_command({"ip", "link", "set", "lo", "up"}) != 0) return "ip link set lo up failed";
  if (run_command({"ip", "route", "add", "224.0.0.0/4", "dev", "lo"}) != 0) return "ip route add 224.0.0.0/4 failed";
  return "";
}

LoadReport run_load_test(const LoadTestConfig& cfg) {
  LoadReport r;
  const std::string url = "udpm://239.255.76.67:" + std::to_string(cfg.port) + "?ttl=0";
  std::vector<std::string> argv = {cfg.server, "--lcm-url", url, "--status-period", "0.5"};
  argv.insert(argv.end(), cfg.server_args.begin(), cfg.server_args.end());
  const std::vector<PosedScan> scans = load_scans(cfg);
  StatusTracker status(url);
  const pid_t server = spawn(argv, cfg.log_path);
  for (int i = 0; i < 600 && status.latest().utime == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (status.latest().utime == 0) {
    ::kill(server, SIGKILL);
    ::waitpid(server, nullptr, 0);
    throw std::runtime_error("the server sent no status within 60 s; see " + cfg.log_path);
  }
  std::atomic<int64_t> published{0}, errors{0};
  const auto t0 = SteadyClock::now();
  std::atomic<bool> series_stop{false};
  std::jthread series;
  if (!cfg.series_path.empty()) {
    series = std::jthread([&] {
      std::ofstream out(cfg.series_path);
      out << "t_s,rss_mib,peak_rss_mib,map_memory_mib,map_nodes,e2e_p99_ms,scans_applied,octree_p99_ms,"
             "bound_mib,evicted_mib,evicted_regions,region_evictions,region_restores\n";
      int64_t last_seq = -1;
      while (!series_stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        const octomap_rt::server_status_t st = status.latest();
        if (st.seq == last_seq) continue;
        last_seq = st.seq;
        char line[384];
        std::snprintf(line, sizeof line, "%.2f,%.1f,%.1f,%.2f,%lld,%.2f,%lld,%.2f,%.2f,%.2f,%lld,%lld,%lld\n",
                      seconds_since(t0), rss_mib(server), peak_rss_mib(server), double(st.memory_bytes) / 1048576.0,
                      (long long)st.num_nodes, double(st.end_to_end_ms_p99), (long long)st.scans_applied,
                      double(st.octree_ms_p99), double(st.map_memory_bound) / 1048576.0,
                      double(st.evicted_bytes) / 1048576.0, (long long)st.evicted_regions,
                      (long long)st.region_evictions, (long long)st.region_restores);
        out << line << std::flush;
      }
    });
  }
  {
    std::vector<std::jthread> producers;
    for (int i = 0; i < cfg.producers; ++i)
      producers.emplace_back([&, i] { publish_for(url, i, cfg, scans, published, errors); });
  }
  const double publish_s = seconds_since(t0);
  r.published = published;
  r.publish_errors = errors;
  // Settle: until every received scan is applied, rejected or dropped (or the time is up).
  const auto settle_end = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                   std::chrono::duration<double>(cfg.settle_s));
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    count_totals(status.latest(), r);
  } while ((r.in_flight > 0 || r.received < r.published - r.missed) && SteadyClock::now() < settle_end);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // one more status period
  count_totals(status.latest(), r);
  status.fill(r);
  r.peak_rss_mib = peak_rss_mib(server);
  series_stop = true;
  if (series.joinable()) series.join();
  r.scans_per_s = publish_s > 0 ? r.applied / publish_s : 0;
  ::kill(server, SIGTERM);
  int st = 0;
  ::waitpid(server, &st, 0);
  r.server_exit = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

void print_load_report(std::ostream& out, const LoadTestConfig& cfg, const LoadReport& r) {
  char line[512];
  out << "octomap-rt load test\n";
  std::snprintf(line, sizeof line, "  load:        %d producers x %.1f Hz x %.0f s, %d points a scan; server %s\n",
                cfg.producers, cfg.rate_hz, cfg.duration_s, cfg.points, [&] {
                  static std::string a;
                  a.clear();
                  for (const auto& s : cfg.server_args) a += s + " ";
                  return a.c_str();
                }());
  out << line;
  std::snprintf(line, sizeof line,
                "  scans:       published %lld, received %lld = applied %lld + rejected %lld + dropped %lld%s; "
                "missed (seq gaps) %lld\n",
                (long long)r.published, (long long)r.received, (long long)r.applied, (long long)r.rejected,
                (long long)r.dropped, r.in_flight ? (" + in flight " + std::to_string(r.in_flight)).c_str() : "",
                (long long)r.missed);
  out << line;
  out << "  accounted:   " << (r.accounted() ? "yes" : "NO") << " (lost before the server: " << r.published - r.received
      << ", kernel drops on the server's socket: " << r.kernel_drops << ")\n";
  std::string drops;
  for (const auto& [k, v] : r.drop_reasons) drops += k + " " + std::to_string(v) + "; ";
  for (const auto& [k, v] : r.reject_reasons) drops += "rejected: " + k + " " + std::to_string(v) + "; ";
  out << "  why:         " << (drops.empty() ? "nothing dropped or rejected" : drops) << "\n";
  std::snprintf(line, sizeof line,
                "  server:      peak RSS %.0f MiB; end-to-end p99 %.0f ms at the end, %.0f ms at most; %.1f scans/s "
                "applied; %lld of %lld statuses DEGRADED; exit %d\n",
                r.peak_rss_mib, r.e2e_p99_ms_last, r.e2e_p99_ms_max, r.scans_per_s, (long long)r.degraded_statuses,
                (long long)r.statuses, r.server_exit);
  out << line;
  out << "  last status: " << r.last_message << "\n";
}

}  // namespace ort::cli
