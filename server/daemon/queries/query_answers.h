// The query service's answers: validation of a decoded query (what the server refuses and
// why), and the reply messages, computed with server/query/ on the map under the caller's
// (shared) map lock and encoded ready to publish (split where one datagram is not enough).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "daemon/queries/query_clients.h"
#include "daemon/queries/query_config.h"
#include "daemon/queries/reply_stamp.h"
#include "query/work_budget.h"

namespace ort::daemon {

// The most cells a grid answer may have (within --query-max-reply-bytes too): the grid query's
// and the grid published at a rate.
inline constexpr int64_t kMaxGridCells = 4'000'000;

// Common to every query message.
struct QueryHeader {
  int64_t request_id = 0, min_snapshot_id = 0, wait_seq = -1;
  int32_t wait_timeout_ms = 0;
  std::string client_id, reply_channel, wait_robot_id;
};
QueryHeader header_of(const QueryMessage& q);

// "" when the query can be answered; else why not (non-finite numbers, counts, depth, ...).
std::string validate_query(const QueryMessage& q, double resolution);

struct EncodedReplies {
  std::string channel;
  std::vector<std::vector<uint8_t>> messages;  // in order; several for regions and grids
  // What the replies say, for the counters: REPLY_OK (cut: answered in part, `error` says
  // where and why), or the refusal of a region or grid past its bound.
  int8_t status = 0;
  bool cut = false;
  std::string error;
  // Work left for after the map lock (distance queries: the EDT): fills `messages`, and
  // `refused` with why when a bound cut the answer after all.
  std::function<void(EncodedReplies&)> finish = {};
  std::string client_id = {}, refused = {};
};

// Under the map lock, within `budget` (its max_work and deadline; regions and grids also
// within bounds.max_reply_bytes). A shard (`shard` sharded) answers a ray for its own regions
// only (docs/PROTOCOL.md, "Shards"). Throws query::QueryError (the caller replies BAD_REQUEST
// with it).
EncodedReplies answer_query(const octomap::OcTree& tree, const QueryMessage& q, const MapStamp& stamp,
                            const std::string& server_id, const QueryBounds& bounds, query::WorkBudget& budget,
                            const protocol::ShardSet& shard = {});
// Why a budget cut a query, with the bound's flag ("the work bound of 4000000 node visits or
// ray steps (--query-max-work)").
std::string cut_reason(const query::WorkBudget& budget, const QueryBounds& bounds);
// A reply of q's type with `status` (occupancy_reply_t.REPLY_*) and `error`, no results.
EncodedReplies error_reply(const QueryMessage& q, int8_t status, const std::string& error, const MapStamp& stamp,
                           const std::string& server_id);

}  // namespace ort::daemon
