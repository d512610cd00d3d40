// What the query service is configured with (server flags --control-token, --query-queue,
// --grid-rate, --grid-z, --grid-cell, --distance-*: server_cli).
#pragma once

#include <cstddef>
#include <string>

#include "distance/distance_queries.h"
#include "protocol/channels.h"
#include "protocol/shards/shard_set.h"
#include "query/edit_cost.h"

namespace ort::daemon {

// The 2D grid published at a rate (daemon/grid_publisher.h).
struct GridPublishConfig {
  double rate_hz = 0;           // 0: not published
  double z_min = 0, z_max = 0;  // the band [m]
  bool z_given = false;         // --grid-z was given: a rate above 0 needs it
  double cell_size = 0;         // [m]; 0: the resolution; else a multiple of it
  std::string channel = ort::protocol::kGridChannel;
};

// What one query may cost (docs/RELIABILITY.md, "Bounded cost"). Past max_work or lock_ms a
// ray or box query is cut (its reply says where), a region or grid query refused.
struct QueryBounds {
  uint64_t max_work = 4'000'000;       // nodes visited or ray key steps (--query-max-work)
  double lock_ms = 10;                 // time under the map's read lock (--query-lock-ms)
  size_t max_reply_bytes = 16u << 20;  // a region's or grid's replies (--query-max-reply-bytes)
};

// Default edit bounds: a clear of a room's box, misaligned, even marking its unknown space,
// stays far below them, and so does a clear of a corridor map's known space; what the bounds
// mean in time under the lock (mapping waits meanwhile): docs/RELIABILITY.md, "Map edits".
inline constexpr int64_t kDefaultMaxEditNewNodes = 1'000'000;
inline constexpr int64_t kDefaultMaxEditWork = 16'000'000;

// Distance queries (daemon/queries/distance_answers.h): where the EDT runs and its bounds.
struct DistanceServiceConfig {
  std::string backend = "cpu";  // cpu | vulkan | auto (vulkan where a GPU that is not a CPU device exists)
  std::string device;           // Vulkan device (index or name substring); "" automatic
  int threads = 2;              // CPU EDT workers
  distance::DistanceLimits limits{.max_grid_cells = 16'000'000, .max_box_cells = 4'000'000};
  int64_t max_reply_bytes = 16 << 20;  // compressed box blob; larger is refused as too large
  int zstd_level = 1;                  // 1..19; negative: zstd's fast levels (same frames); 0: none
  // Cells of a box reply's z-slab (box_frames.h's kSlabCells): slabs compressed apart on the
  // EDT's threads, an unchanged slab's frame kept; 0: the box one frame on one thread.
  int64_t reply_slab_cells = 65536;
  bool field_cache = true;  // keep the last field for the next query (distance/field_cache.h)
  // Bring the cached field's grid up to date from the scans' change lists
  // (daemon/map/change_journal.h) instead of reading its box from the map again.
  bool change_lists = true;
  // The server's shard set (ServerConfig::shard, set where the query service is made): a
  // shard answers for the obstacles of its own regions (distance_types.h's RegionOwnership).
  protocol::ShardSet shard;
};

struct QueryServiceConfig {
  std::string points_channel = ort::protocol::kQueryChannel;
  std::string rays_channel = ort::protocol::kQueryRaysChannel;
  std::string boxes_channel = ort::protocol::kQueryBoxesChannel;
  std::string grid_channel = ort::protocol::kQueryGridChannel;
  std::string distance_channel = ort::protocol::kQueryDistanceChannel;
  std::string edit_channel = ort::protocol::kMapEditChannel;
  // The server's own inputs and heartbeat: a reply_channel naming one of them is refused.
  std::string scan_prefix = ort::protocol::kScanChannelPrefix;
  std::string status_channel = ort::protocol::kStatusChannel;
  std::string control_token;      // "": every edit is refused; else the key of the edits' MAC
  double edit_window_s = 30;      // an edit's utime at most this far from the server's clock
  size_t max_edit_nonces = 4096;  // edits admitted within the window (the replay cache's bound)
  // An edit whose estimated cost passes these is refused before it starts (--max-edit-nodes,
  // --max-edit-work): it would hold the map's exclusive lock, and mapping, that long.
  query::EditBounds edit_bounds{kDefaultMaxEditNewNodes, kDefaultMaxEditWork};
  size_t per_client_queue = 16;       // queued queries per client; more get BUSY
  size_t max_clients = 256;           // distinct client ids tracked; the rest share "*"
  double client_idle_expiry_s = 600;  // a client idle this long gives its slot to a new one
  int max_wait_ms = 30000;            // longest wait_timeout_ms honoured
  QueryBounds bounds;
  GridPublishConfig grid;
  DistanceServiceConfig distance;
  // Pause between two messages of one reply (a distance box's chunks, regions, grids): 60 KB
  // datagrams in a burst overrun default receive buffers (lcm-1.3.1 notes §3.3). 0: none (memq://,
  // or receive buffers sized for the burst).
  double reply_chunk_interval_ms = 0.5;
  // The server's shard set (ServerConfig::shard, set where the query service is made): a
  // shard's rays stop only in its own regions (query/ray_query.h's RayBatchOptions::owns).
  protocol::ShardSet shard;
};

}  // namespace ort::daemon
