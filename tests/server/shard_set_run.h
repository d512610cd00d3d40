// The set-up the shard-set integration tests share (shards_integration_test,
// shard_mirror_integration_test): a private network namespace, `count` octomap-rt-server
// --shard i/count processes in one map namespace on the CPU back end, a listener for their
// statuses, and a robot ("rover") that publishes real scans to the set over udpm.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "cli/replay/scan_message.h"
#include "core/clock.h"
#include "integration_harness.h"
#include "scene/scan_set.h"

namespace ort::test {

class ShardSetRun {
 public:
  // Enters a fresh network namespace; nothing else starts until start() (and only when ok()).
  explicit ShardSetRun(const std::string& tag) : netns_(tag), dir(make_test_dir(tag)) {}

  const NetworkNamespace& netns() const { return netns_; }

  // Starts the shards (the common flags, then `extra`) and waits for each one's first status.
  ::testing::AssertionResult start(const std::string& ns, int count, double resolution,
                                   const std::vector<std::string>& extra) {
    if (!netns_.ok()) return ::testing::AssertionFailure() << "no network namespace: " << netns_.error();
    ns_ = ns;
    url = test_lcm_url(7, netns_.rmem_max());
    client_url = url.substr(0, url.find("&recv_buf_size"));
    status = std::make_unique<StatusWatcher>(url, protocol::channels_in(ns).status);
    for (int i = 0; i < count; ++i) {
      std::vector<std::string> argv{server_program(),
                                    "--lcm-url",
                                    url,
                                    "-r",
                                    std::to_string(resolution),
                                    "--namespace",
                                    ns,
                                    "--shard",
                                    std::to_string(i) + "/" + std::to_string(count),
                                    "--warm-up-points",
                                    "0",
                                    "--backend",
                                    "cpu"};
      argv.insert(argv.end(), extra.begin(), extra.end());
      shards.push_back(std::make_unique<ChildProcess>(argv, dir + "/shard" + std::to_string(i) + ".log"));
    }
    for (auto& s : shards)
      if (!status->wait_for([&](const auto& m) { return m.pid == s->pid(); }, 60))
        return ::testing::AssertionFailure() << "no status from a shard in 60 s: " << s->log();
    robot = std::make_unique<lcm::LCM>(client_url);
    if (!robot->good()) return ::testing::AssertionFailure() << "the robot's LCM on " << client_url << " failed";
    return ::testing::AssertionSuccess();
  }

  // The robot publishes `scan` as its scan `seq`.
  void publish(const PosedScan& scan, int64_t seq) {
    cli::ScanMessageFields fields;
    fields.robot_id = "rover", fields.seq = seq, fields.utime = now_utime();
    const octomap_rt::scan_t msg = cli::make_scan_message(scan, fields);
    robot->publish(cli::scan_channel(protocol::channels_in(ns_).scan_prefix, "rover"), &msg);
  }

  // Every shard still running has applied `n` scans in all (each keeps its own regions' voxels).
  ::testing::AssertionResult all_applied(int64_t n, double timeout_s) {
    for (auto& s : shards)
      if (!status->wait_for([&](const auto& m) { return m.pid == s->pid() && total_applied(m) == n; }, timeout_s))
        return ::testing::AssertionFailure()
               << "a shard did not apply " << n << " scans in " << timeout_s << " s: " << s->log();
    return ::testing::AssertionSuccess();
  }

 private:
  NetworkNamespace netns_;  // first: every socket and child below lives in it
  std::string ns_;

 public:
  const std::string dir;
  std::string url, client_url;  // client_url: without the receive buffer (the CLI's and the queries')
  std::unique_ptr<StatusWatcher> status;
  std::vector<std::unique_ptr<ChildProcess>> shards;
  std::unique_ptr<lcm::LCM> robot;
};

}  // namespace ort::test
