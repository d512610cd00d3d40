// What every `octomap-rt query` subcommand shares: the connection, wait and output flags,
// the client made from them, and the refusal rule (reason on stderr, exit status 2).
#pragma once

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <memory>
#include <string>

#include "cli/namespace_flag.h"
#include "cli/shard_commands.h"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "query_client/query_client.h"
#include "query_client/query_json.h"

namespace ort::cli {

using namespace ort::client;

struct CommonArgs {
  std::string lcm_url, client_id, ns;
  double timeout_s = 5;
  bool json = false, shards = false;  // shards: query_command.cpp's --shards
  std::string wait_robot;
  int64_t wait_seq = -1;
  int64_t min_snapshot = 0;
};

inline void add_common(CLI::App* cmd, CommonArgs& a) {
  cmd->add_option("--lcm-url", a.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL, else the host-local udpm URL)");
  add_namespace_flag(cmd, a.ns);
  cmd->add_option("--timeout", a.timeout_s, "seconds to wait for the answer")->capture_default_str();
  cmd->add_flag("--json", a.json, "one JSON document on stdout");
  cmd->add_option("--client-id", a.client_id, "client name (default cli-<pid>); replies come on OCTOMAP_RT_REPLY_<ID>");
  cmd->add_option("--wait-robot", a.wait_robot, "answer only once this robot's --wait-seq scan is applied");
  cmd->add_option("--wait-seq", a.wait_seq, "the scan seq to wait for (with --wait-robot)");
  cmd->add_option("--min-snapshot", a.min_snapshot, "answer from map state >= this");
}

inline std::unique_ptr<QueryClient> connect(const CommonArgs& a) {
  const std::string id = a.client_id.empty() ? "cli-" + std::to_string(::getpid()) : a.client_id;
  return std::make_unique<QueryClient>(ort::protocol::lcm_url_or_default(a.lcm_url), id,
                                       std::chrono::milliseconds(static_cast<int64_t>(a.timeout_s * 1000)),
                                       protocol::namespace_from(a.ns));
}

// --shards (query_command.cpp): the flag, and the namespace's shard set found by its statuses
// with a client routing to it (--wait-robot goes to every shard asked; no --min-snapshot: each
// shard has its own map states).
void add_shards_flag(CLI::App* cmd, CommonArgs& a);
std::unique_ptr<ShardQueries> connect_shards(const CommonArgs& a);

// A routed answer's reply; `partial` when a shard's part is missing (said on stderr: exit 3).
template <class R>
R routed(const Routed<R>& r, bool& partial) {
  partial = say_partial(r.shards);
  return r.reply;
}

inline WaitFor wait_for(const CommonArgs& a) {
  WaitFor w;
  w.min_snapshot_id = a.min_snapshot;
  w.robot_id = a.wait_robot;
  w.seq = a.wait_seq;
  w.timeout_ms = static_cast<int>(a.timeout_s * 1000 * 0.8);
  return w;
}

// --wait-robot / --wait-seq for every shard asked (ShardWait).
inline ShardWait shard_wait(const CommonArgs& a) {
  ShardWait w;
  w.robot_id = a.wait_robot;
  w.seq = a.wait_seq;
  w.timeout_ms = static_cast<int>(a.timeout_s * 1000 * 0.8);
  return w;
}

// Non-OK replies: the reason on stderr, exit status 2.
template <class R>
bool refused(const R& r) {
  if (r.status == 0) return false;
  std::cerr << "octomap-rt query: " << status_name(r.status) << ": " << r.error << "\n";
  return true;
}

// `octomap-rt query distance points|box|path` (query/distance_command.cpp).
void register_distance_command(CLI::App& query);

}  // namespace ort::cli
