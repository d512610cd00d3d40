// The shards of one namespace, as their statuses announce them (docs/PROTOCOL.md, "Shards"):
// every shard publishes server_status_t on the namespace's status channel with the whole
// shard set it belongs to, so a client that heard one knows how many to wait for and can say
// which are missing or late. Every status is decoded inside try/catch and its shard fields
// range-checked (protocol/shards/shard_wire.h); refusals are counted by reason.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "octomap_rt/server_status_t.hpp"
#include "protocol/shards/shard_set.h"

namespace ort::client {

class ShardRoster {
 public:
  struct Member {
    octomap_rt::server_status_t status;
    int64_t received_utime = 0;
  };

  // One status message's raw bytes, received at `received_utime` (now_utime's clock).
  void take(const void* data, size_t size, int64_t received_utime);

  // The set the first usable status announced; nullopt before one came.
  const std::optional<protocol::ShardSet>& set() const { return set_; }
  // The newest status of each shard heard, by shard index.
  const std::map<uint32_t, Member>& members() const { return members_; }
  // Statuses not taken, by reason ("undecodable", the shard fields' faults, "another shard set").
  const std::map<std::string, int64_t>& refused() const { return refused_; }
  // The set's resolution [m] (the first member's; 0 before one).
  double resolution() const;

  bool complete() const { return set_ && members_.size() == set_->count; }
  std::vector<uint32_t> missing() const;
  // Members whose newest status is older than `late_after_s` at `now_utime`.
  std::vector<uint32_t> late(int64_t now_utime, double late_after_s) const;
  // What a partial answer says: "shard 2 of 3 not heard; shard 1 late (last status 4.2 s ago)";
  // "" when every shard is in and fresh.
  std::string shortfall(int64_t now_utime, double late_after_s) const;

 private:
  void refuse(const std::string& why) { refused_[why]++; }
  std::optional<protocol::ShardSet> set_;
  std::map<uint32_t, Member> members_;
  std::map<std::string, int64_t> refused_;
};

// Listens to namespace `ns`'s status channel on `url` until every shard of the announced set
// was heard or `timeout_s` passed (a server that is not sharded is a set of one).
ShardRoster discover_shards(const std::string& url, const std::string& ns, double timeout_s);

}  // namespace ort::client
