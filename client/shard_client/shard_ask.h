// How ShardQueries asks its shards (shard_queries.cpp, shard_grid_edit.cpp): side by side,
// each answer or the reason it is missing.
#pragma once

#include <functional>
#include <future>
#include <optional>
#include <stdexcept>
#include <vector>

#include "octomap_rt/occupancy_reply_t.hpp"
#include "query_client/query_client.h"
#include "shard_client/shard_queries.h"

namespace ort::client::detail {

// The status and map state of a reply (a distance box's are in its first chunk).
template <class Reply>
const Reply& head(const Reply& r) {
  return r;
}
inline const octomap_rt::distance_box_chunk_t& head(const DistanceBox& b) { return b.header; }
inline const octomap_rt::grid_t& head(const Grid& g) { return g.header; }
// A region list's is in its first chunk (the caller asks only for lists with one).
inline const octomap_rt::region_chunk_t& head(const std::vector<octomap_rt::region_chunk_t>& c) { return c.front(); }

// Runs ask(i) for every shard i in `which` side by side; each result or the reason it failed.
template <class Reply>
std::vector<std::optional<Reply>> ask_each(const std::vector<uint32_t>& which, size_t count, ShardAnswer& answer,
                                           const std::function<Reply(uint32_t)>& ask) {
  std::vector<std::optional<Reply>> out(count);
  std::vector<std::pair<uint32_t, std::future<Reply>>> pending;
  for (uint32_t i : which) pending.emplace_back(i, std::async(std::launch::async, ask, i));
  answer.snapshot_ids.assign(count, -1);
  for (auto& [i, f] : pending) {
    try {
      Reply r = f.get();
      if (head(r).status != octomap_rt::occupancy_reply_t::REPLY_OK)
        throw std::runtime_error("refused: " + head(r).error);
      answer.snapshot_ids[i] = head(r).snapshot_id;
      out[i] = std::move(r);
    } catch (const std::exception& e) {
      answer.missing.push_back(i);
      answer.errors.push_back(e.what());
    }
  }
  return out;
}

inline std::vector<uint32_t> every_shard(uint32_t count) {
  std::vector<uint32_t> v(count);
  for (uint32_t i = 0; i < count; ++i) v[i] = i;
  return v;
}

}  // namespace ort::client::detail
