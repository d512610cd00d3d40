// What the daemon's integration tests share: a private network namespace for their LCM
// multicast traffic, child processes (daemon, producers, lcm-logger) with logs, and a
// listener for the daemon's status heartbeats.
//
// Isolation (../shared/notes/lcm-1.3.1.md §7): the test process itself moves into a fresh
// network namespace, so every child it starts (and every LCM socket it opens) is there too;
// nothing reaches the host's interfaces, and ttl=0 besides. `ip netns add` when we are root,
// else an unprivileged `unshare(CLONE_NEWUSER | CLONE_NEWNET)` of this process.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <octomap/OcTree.h>
#include <lcm/lcm-cpp.hpp>

#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"

namespace ort::test {

class NetworkNamespace {
 public:
  // Creates the namespace, enters it (this thread; call from the main thread before any
  // LCM object or child exists), brings lo up and routes multicast over it.
  explicit NetworkNamespace(const std::string& tag);
  ~NetworkNamespace();
  NetworkNamespace(const NetworkNamespace&) = delete;
  NetworkNamespace& operator=(const NetworkNamespace&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const std::string& how() const { return how_; }  // "ip netns <name>" or "unshare"
  // net.core.rmem_max as seen inside (read-only there: the host's value).
  int64_t rmem_max() const;

 private:
  std::string name_, how_, error_;
  int home_fd_ = -1;  // the namespace we came from, to return to
};

// An LCM URL for one test: its own port (derived from the pid and `slot`), ttl=0, and a
// receive buffer no larger than rmem_max allows.
std::string test_lcm_url(int slot, int64_t rmem_max);

// A child process with stdout+stderr going to a log file. Killed (SIGKILL) when destroyed
// while still running.
class ChildProcess {
 public:
  ChildProcess(const std::vector<std::string>& argv, const std::string& log_path,
               const std::vector<std::string>& extra_env = {});
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  bool running();
  void signal(int sig);
  // Exit status (0-255), 128+signal when killed, or nullopt on timeout.
  std::optional<int> wait(double timeout_s);
  const std::string& log_path() const { return log_path_; }
  std::string log() const;

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::string log_path_;
};

// Decodes every OCTOMAP_RT_STATUS on its own LCM instance and thread.
class StatusWatcher {
 public:
  StatusWatcher(const std::string& url, const std::string& channel = ort::protocol::kStatusChannel);
  ~StatusWatcher();
  bool good() const { return good_; }
  // Waits until a status satisfying `pred` arrives (or already has); returns it.
  std::optional<octomap_rt::server_status_t> wait_for(
      const std::function<bool(const octomap_rt::server_status_t&)>& pred, double timeout_s);
  std::optional<octomap_rt::server_status_t> latest() const;
  // Forgets what was received (e.g. before a daemon restart).
  void clear();

 private:
  static void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel, StatusWatcher* self);
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM lcm_;
  bool good_ = false;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::optional<octomap_rt::server_status_t> latest_;
  bool stop_ = false;
  std::thread thread_;
};

// Producer counters by robot id (case-insensitive: the server names producers by their
// channel suffix, which is upper case) from a status message; nullptr if absent.
const octomap_rt::robot_stats_t* find_robot_ci(const octomap_rt::server_status_t& s, const std::string& robot_id);
// Robot ids compare case-insensitively (channel suffixes are upper case).
bool same_robot(const std::string& a, const std::string& b);
// i for robot "<prefix><i>" (case-insensitive) with 0 <= i < n, else -1.
int producer_index(const std::string& robot_id, const std::string& prefix, int n);
// Sum of scans_applied over all robots.
int64_t total_applied(const octomap_rt::server_status_t& s);

// Reads an .ot map; nullptr (and a test failure) if it is not a loadable OcTree.
std::unique_ptr<octomap::OcTree> load_ot(const std::string& path);

// A fresh temporary directory for one test (kept on failure for inspection).
std::string make_test_dir(const std::string& tag);

// Paths of the programs under test (compiled in by tests.cmake).
std::string server_program();
std::string client_program();

}  // namespace ort::test
