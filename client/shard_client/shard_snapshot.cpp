#include "shard_client/shard_snapshot.h"

#include <future>
#include <stdexcept>

#include "map_client/map_client.h"
#include "map_client/shard_merge.h"
#include "protocol/shards/shard_set.h"

namespace ort::client {
namespace {

struct Fetched {
  ShardPart part;
  std::unique_ptr<octomap::OcTree> tree;
};

// Shard `index`'s snapshot from the map protocol of namespace `served_in`.
Fetched fetch_one(const std::string& url, const std::string& served_in, uint32_t index, double timeout_s) {
  Fetched f;
  f.part.index = index;
  try {
    MapClient c(url, ClientOptions{}.in_namespace(served_in));
    const FetchedSnapshot s = c.fetch_snapshot(octomap_rt::map_chunk_t::FORMAT_OCTOMAP_FULL, timeout_s);
    f.tree = s.tree();
    f.part.fetched = true;
    f.part.snapshot_id = s.snapshot_id;
    f.part.num_scans = s.num_scans;
    f.part.epoch = s.map_epoch;
    f.part.bytes = static_cast<int64_t>(s.bytes.size());
    f.part.seconds = s.seconds;
  } catch (const std::exception& e) {
    f.part.error = e.what();
  }
  return f;
}

}  // namespace

MergedMap fetch_merged_map(const std::string& url, const std::string& ns, const ShardRoster& roster, double timeout_s) {
  if (!roster.set()) throw std::runtime_error("no shard of namespace '" + ns + "' was heard");
  const protocol::ShardSet& set = *roster.set();
  MergedMap out;
  out.parts.resize(set.count);
  std::vector<std::future<Fetched>> pending;
  for (uint32_t i = 0; i < set.count; ++i) {
    out.parts[i].index = i;
    if (!roster.members().count(i)) {
      out.parts[i].error = "not heard (no status)";
      continue;
    }
    // A server that is not sharded serves on the namespace itself.
    const std::string served_in = set.sharded() ? protocol::shard_namespace(ns, i) : ns;
    pending.push_back(std::async(std::launch::async, fetch_one, url, served_in, i, timeout_s));
  }
  std::vector<std::unique_ptr<octomap::OcTree>> trees;
  for (auto& p : pending) {
    Fetched f = p.get();
    out.parts[f.part.index] = f.part;
    if (f.tree) trees.push_back(std::move(f.tree));
  }
  std::vector<const octomap::OcTree*> views;
  for (const auto& t : trees) views.push_back(t.get());
  for (const ShardPart& p : out.parts)
    if (!p.fetched) {
      out.partial = true;
      out.shortfall += (out.shortfall.empty() ? "" : "; ") + std::string("shard ") + std::to_string(p.index) + " of " +
                       std::to_string(set.count) + " missing: " + p.error;
    }
  if (!views.empty()) out.tree = merge_shard_trees(views, set.region_depth);
  return out;
}

}  // namespace ort::client
