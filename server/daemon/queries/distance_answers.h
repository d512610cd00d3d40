// Distance queries (distance_query_t) in the query service: validation, the read of the
// map under the caller's shared lock (distance::read_*, bounded by the limits), and the rest
// (the EDT, on CPU threads or the Vulkan device, the field read, zstd, the reply messages)
// deferred to after the lock, so that stage 2 waits only for the copy out of the tree.
#pragma once

#include <string>

#include <octomap/OcTree.h>

#include "daemon/map/change_journal.h"
#include "daemon/queries/query_answers.h"
#include "daemon/queries/query_config.h"
#include "distance/distance_queries.h"
#include "distance/field_cache.h"
#include "octomap_rt/distance_query_t.hpp"

namespace ort::daemon {

// "" when the query can be answered as asked (limits checked that need no map), else why not.
std::string validate_distance(const octomap_rt::distance_query_t& q, double resolution,
                              const DistanceServiceConfig& cfg);

// Under the map lock: reads what the answer needs; the returned replies have no messages
// yet and a `finish` that computes them after the lock. Throws distance::DistanceError.
// `cache` (may be null): the last field, reused where the grid read is its box's
// (distance/field_cache.h); the finish calls must then run in the order of the reads, on one
// thread, while the cache lives. `journal` (may be null): the map's change lists, from which
// the cached box's grid is brought up to date instead of read again (daemon/queries/field_patch.h);
// `stamp.snapshot_id` must be the state of `tree`.
EncodedReplies read_distance(const octomap::OcTree& tree, const octomap_rt::distance_query_t& q, const MapStamp& stamp,
                             const std::string& server_id, const DistanceServiceConfig& cfg,
                             const distance::SquaredEdt& edt, distance::FieldCache* cache = nullptr,
                             ChangeJournal* journal = nullptr);

// A reply of the distance query's mode with `status` and `error`, no results.
std::vector<uint8_t> distance_error_message(const octomap_rt::distance_query_t& q, int8_t status,
                                            const std::string& error, const MapStamp& stamp,
                                            const std::string& server_id);

}  // namespace ort::daemon
