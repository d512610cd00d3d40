// The shard-set side of `octomap-rt map get|status|query --shards` (docs/PROTOCOL.md,
// "Shards"): find the shards of a namespace by their statuses, then merge, lay out side by
// side or route, saying out loud which shard is missing or late.
#pragma once

#include <string>

#include "query_client/query_client.h"
#include "shard_client/shard_queries.h"
#include "shard_client/shard_roster.h"

namespace ort::cli {

struct MapArgs;

// `map get --shards -o FILE.bt|.ot`: every shard's .ot, merged; without `partial` a missing
// shard fails the command and nothing is written. Returns the exit status.
int run_get_shards(const MapArgs& a, const std::string& out_path, bool partial);

// `status --shards`: the shards side by side (text) or one JSON object; 0, or 3 when a shard is
// missing or late.
int run_status_shards(const std::string& url, const std::string& ns, double timeout_s, bool json);
// The same into `text` (what `status --watch --shards` redraws); returns the exit status.
int shard_status_screen(const std::string& url, const std::string& ns, double timeout_s, bool json, std::string& text);

// The shard set of namespace `ns` for `query --shards` (throws when none is heard); a missing
// shard is said on stderr.
client::ShardRoster find_shards_for_query(const std::string& url, const std::string& ns, double timeout_s);
// After a routed answer: its shortfall on stderr ("PARTIAL answer: ..."); true when partial.
bool say_partial(const client::ShardAnswer& a);

}  // namespace ort::cli
