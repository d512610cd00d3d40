#include "integration_harness.h"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/clock.h"

extern char** environ;

namespace ort::test {
namespace {

// Runs a command (no shell), waits; returns its exit status, or -1 if it could not run.
int run_quietly(const std::vector<std::string>& argv) {
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int devnull = open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      dup2(devnull, STDOUT_FILENO);
      dup2(devnull, STDERR_FILENO);
    }
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out);
}

std::string errno_text(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

}  // namespace

NetworkNamespace::NetworkNamespace(const std::string& tag) {
  home_fd_ = open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  // As root: a named namespace (visible to `ip netns`, deleted by name at the end).
  name_ = "ortit-" + tag + "-" + std::to_string(getpid());
  if (geteuid() == 0 && run_quietly({"ip", "netns", "add", name_}) == 0) {
    const int fd = open(("/var/run/netns/" + name_).c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0 && setns(fd, CLONE_NEWNET) == 0) {
      how_ = "ip netns " + name_;
    } else {
      error_ = errno_text("setns into the new namespace");
    }
    if (fd >= 0) close(fd);
  } else {
    // Unprivileged fallback (the `unshare -rn` of the notes): a user namespace in which we
    // are root, with a network namespace of its own. Irreversible for this process.
    name_.clear();
    const uid_t uid = geteuid();
    const gid_t gid = getegid();
    if (unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0) {
      error_ = errno_text("ip netns add failed and unshare(CLONE_NEWUSER|CLONE_NEWNET) too");
    } else {
      write_text("/proc/self/setgroups", "deny");
      write_text("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1\n");
      write_text("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1\n");
      how_ = "unshare";
    }
  }
  if (!error_.empty()) return;
  if (run_quietly({"ip", "link", "set", "lo", "up"}) != 0) {
    error_ = "ip link set lo up failed in the new namespace";
  } else if (run_quietly({"ip", "route", "add", "224.0.0.0/4", "dev", "lo"}) != 0) {
    error_ = "ip route add 224.0.0.0/4 dev lo failed in the new namespace";
  }
}

NetworkNamespace::~NetworkNamespace() {
  if (!name_.empty()) {
    if (home_fd_ >= 0) setns(home_fd_, CLONE_NEWNET);
    run_quietly({"ip", "netns", "del", name_});
  }
  if (home_fd_ >= 0) close(home_fd_);
}

int64_t NetworkNamespace::rmem_max() const {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  int64_t v = -1;
  in >> v;
  return in ? v : -1;
}

std::string test_lcm_url(int slot, int64_t rmem_max) {
  // Each test has its own namespace already; a distinct port as well keeps two runs apart
  // even if one fell back to sharing a namespace (LCM 1.3.1 binds INADDR_ANY: the port, not
  // the group, isolates).
  const int port = 20000 + static_cast<int>((getpid() * 7 + slot * 131) % 20000);
  int64_t buf = 4194304;
  if (rmem_max > 0 && rmem_max < buf) buf = rmem_max;
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=" + std::to_string(buf);
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& log_path,
                           const std::vector<std::string>& extra_env)
    : log_path_(log_path) {
  const int log_fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) throw std::runtime_error(errno_text(("open " + log_path).c_str()));
  pid_ = fork();
  if (pid_ < 0) {
    close(log_fd);
    throw std::runtime_error(errno_text("fork"));
  }
  if (pid_ == 0) {
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    for (const std::string& e : extra_env) putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    std::fprintf(stderr, "exec %s: %s\n", args[0], std::strerror(errno));
    _exit(127);
  }
  close(log_fd);
}

ChildProcess::~ChildProcess() {
  if (running()) {
    kill(pid_, SIGKILL);
    wait(10);
  }
}

bool ChildProcess::running() {
  if (status_ || pid_ <= 0) return false;
  int st = 0;
  const pid_t r = waitpid(pid_, &st, WNOHANG);
  if (r == pid_) {
    status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return false;
  }
  return r == 0;
}

void ChildProcess::signal(int sig) {
  if (running()) kill(pid_, sig);
}

std::optional<int> ChildProcess::wait(double timeout_s) {
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(timeout_s);
  while (running()) {
    if (SteadyClock::now() > deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return status_;
}

std::string ChildProcess::log() const {
  std::ifstream in(log_path_);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

StatusWatcher::StatusWatcher(const std::string& url, const std::string& channel) : lcm_(url) {
  good_ = lcm_.good();
  if (!good_) return;
  lcm_.subscribeFunction(channel, &StatusWatcher::dispatch, this);
  thread_ = std::thread([this] {
    for (;;) {
      {
        std::lock_guard lock(mutex_);
        if (stop_) return;
      }
      if (lcm_.handleTimeout(50) < 0) return;
    }
  });
}

void StatusWatcher::dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel, StatusWatcher* self) {
  self->on_status(rbuf, channel);
}

StatusWatcher::~StatusWatcher() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  if (thread_.joinable()) thread_.join();
}

void StatusWatcher::on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  octomap_rt::server_status_t s;
  try {  // exceptions must not cross LCM's C dispatch frames
    if (s.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0) return;
  } catch (const std::exception&) {
    return;
  }
  {
    std::lock_guard lock(mutex_);
    latest_ = std::move(s);
  }
  cv_.notify_all();
}

std::optional<octomap_rt::server_status_t> StatusWatcher::wait_for(
    const std::function<bool(const octomap_rt::server_status_t&)>& pred, double timeout_s) {
  std::unique_lock lock(mutex_);
  const bool ok =
      cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return latest_ && pred(*latest_); });
  if (!ok) return std::nullopt;
  return latest_;
}

std::optional<octomap_rt::server_status_t> StatusWatcher::latest() const {
  std::lock_guard lock(mutex_);
  return latest_;
}

void StatusWatcher::clear() {
  std::lock_guard lock(mutex_);
  latest_.reset();
}

namespace {
bool same_ci(const std::string& a, const std::string& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::toupper(static_cast<unsigned char>(x)) == std::toupper(static_cast<unsigned char>(y));
         });
}
}  // namespace

bool same_robot(const std::string& a, const std::string& b) { return same_ci(a, b); }

const octomap_rt::robot_stats_t* find_robot_ci(const octomap_rt::server_status_t& s, const std::string& robot_id) {
  for (const auto& r : s.robots) {
    if (same_ci(r.robot_id, robot_id)) return &r;
  }
  return nullptr;
}

int producer_index(const std::string& robot_id, const std::string& prefix, int n) {
  for (int i = 0; i < n; ++i) {
    if (same_ci(robot_id, prefix + std::to_string(i))) return i;
  }
  return -1;
}

std::unique_ptr<octomap::OcTree> load_ot(const std::string& path) {
  std::unique_ptr<octomap::AbstractOcTree> t(octomap::AbstractOcTree::read(path));
  auto* tree = dynamic_cast<octomap::OcTree*>(t.get());
  if (!tree) {
    ADD_FAILURE() << path << " is not a loadable OcTree (.ot)";
    return nullptr;
  }
  t.release();
  return std::unique_ptr<octomap::OcTree>(tree);
}

int64_t total_applied(const octomap_rt::server_status_t& s) {
  int64_t n = 0;
  for (const auto& r : s.robots) n += r.scans_applied;
  return n;
}

std::string make_test_dir(const std::string& tag) {
  const char* base = std::getenv("TMPDIR");
  std::string templ = std::string(base && *base ? base : "/tmp") + "/ortit-" + tag + "-XXXXXX";
  if (!mkdtemp(templ.data())) throw std::runtime_error(errno_text("mkdtemp"));
  return templ;
}

std::string server_program() { return OCTOMAP_RT_SERVER; }
std::string client_program() { return OCTOMAP_RT_CLI; }

}  // namespace ort::test
