// Everything octomap-rt-server is configured with (flags or config file; see server_cli).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "daemon/map/map_upkeep.h"
#include "daemon/pipeline/point_filters.h"
#include "daemon/pipeline/scan_cost_gate.h"
#include "daemon/queries/query_config.h"
#include "daemon/serving/delta_publisher.h"
#include "daemon/serving/map_service.h"
#include "daemon/serving/octomap_raw_publisher.h"
#include "daemon/status/status_reporter.h"
#include "engine/map_engine.h"
#include "protocol/channels.h"
#include "protocol/limits.h"
#include "protocol/shards/shard_set.h"

namespace ort::daemon {

// One convention: a service's own settings are its config struct, nested here as the flags and
// --config set them (serving, deltas, status, octomap_raw, queries, upkeep, scan_costs); the
// server adds only what it learns at start (its id, the map's resolution) before handing
// each one over. The flat fields are the server's own: transport, intake, persistence, the
// pipeline's lifecycle, the memory bound and the replica.
struct ServerConfig {
  PointFilters point_filters;  // octomap_server's pass-through and a min range, before preparation
  EngineOptions engine;        // resolution, sensor model, max range, back end
  // Every channel below is NS_ + its name when ns is set (--namespace; protocol/channels.h).
  std::string ns;
  std::string lcm_url;                 // "": $LCM_DEFAULT_URL, else host-local udpm
  uint64_t recv_buf_size = 16u << 20;  // udpm receive buffer wanted (capped by rmem_max)
  std::string scan_channels =
      (std::string(ort::protocol::kScanChannelPrefix) + ".*");  // regex; its literal prefix + robot id
  std::string map_path;                                         // .ot; "": no persistence
  // A map to start from when map_path does not exist yet (or without map_path): .bt or .ot
  // (octomap_server's map file). "": none. A new history (docs/PROTOCOL.md "Ids").
  std::string prior_path;
  // -r was not given: map at the resolution of map_path (when it exists), else of prior_path.
  bool resolution_from_file = false;
  bool move_corrupt_map_aside = false;  // corrupt map: keep it as FILE.corrupt-<time>, start anew
  std::string applied_log;              // live applied-order log; "": none
  double save_interval_s = 30;          // <= 0: save only at exit
  StatusReporterConfig status;          // the heartbeat's channel and period
  bool pipeline = true;                 // false: both stages on one thread
  // Points of the synthetic scan the engine shoots and applies to a scratch tree before the
  // intake opens (engine/engine_warm_up.h), so the first scans pay no one-time costs; 0: none.
  // Default: one VGA depth image (640 x 480).
  size_t warm_up_points = 640 * 480;
  std::string server_id;                                       // "": octomap-rt-server@<host>
  uint64_t queue_budget_bytes = 0;                             // per producer; 0: automatic_queue_budget()
  uint64_t max_points = ort::protocol::kDefaultMaxScanPoints;  // per scan
  size_t max_producers = 64;
  ScanCostBounds scan_costs;                // per producer over time: origin jumps, voxels, new nodes a second
  double producer_idle_release_s = 600;     // an idle producer's slot goes to a new robot; <= 0: never
  std::vector<std::string> allowed_robots;  // --allow-robot; empty: any valid robot id
  int lcm_queue_capacity = 64;              // LCM's own per-subscription queue (messages)
  OctomapRawConfig octomap_raw;
  // Serving the map (docs/PROTOCOL.md): snapshots on request and the info message; the server
  // fills in its id, resolution, region and shard at start.
  MapServiceConfig serving;
  // Deltas (rate <= 0: none); their zstd level and pacing are the snapshots' (serving).
  DeltaConfig deltas;
  QueryServiceConfig queries;  // queries and map edits (daemon/query_service.h)
  // Overload: a scan that waited longer than this in the queue is dropped ("over latency
  // bound") instead of applied late, and the status is DEGRADED while the end-to-end p99
  // exceeds it. <= 0: never shed.
  double latency_bound_s = 5.0;
  // Stop: queued scans are applied for at most this long; what is still queued then is
  // dropped ("left at shutdown") and the map as applied is saved.
  double drain_timeout_s = 5.0;
  // DEGRADED when a pipeline stage has been on one scan for longer than this.
  double stuck_stage_s = 30.0;
  // The long-lived map: decay, clearing by distance (daemon/map/map_upkeep.h).
  UpkeepConfig upkeep;
  // The regions this daemon maps when it is one shard of several (--shard, --shard-box;
  // protocol/shards/shard_set.h); the default maps every region.
  protocol::ShardSet shard;
  // The memory bound (daemon/map/map_residency.h): past this many bytes of tree, the least
  // recently touched regions (--evict-depth) go to FILE.ot.regions/; 0: no bound.
  uint64_t max_map_memory = 0;
  // Its working set (--working-set-seconds): below the bound, regions touched within this many
  // seconds stay in memory (octree/residency/working_set_window.h); 0: T follows the robots'
  // scan rate.
  double working_set_s = 0;
  uint64_t region_store_max_bytes = uint64_t(1) << 40;  // the store's own bound on disk
  // Depth of the regions the bound evicts and restores: finer than decay's and clearing's
  // regions (--region-depth), so that a scan brings back little more than it sees; 0: one
  // level below --region-depth (at most 16).
  unsigned evict_depth = 0;
  // Whole-map readers (snapshots, saves, the viewer publisher, status counts) read a replica
  // of the map fed by stage 2 (daemon/map/map_replica.h), so they never hold the octree stage
  // up; it costs one more tree in memory and a second octree update per scan on another
  // thread. false: they copy the map of record under its lock.
  bool read_replica = true;
  // Changes the replica may lag behind by; past it, stage 2 waits for it (outside the map lock),
  // or with replica_rebuild_slice_nodes > 0 the replica falls behind and rebuilds from the map
  // of record in slices of at most that many copied nodes (stage 2 never waits; whole-map
  // readers copy the map of record until it caught up: daemon/map/map_replica.h).
  uint64_t replica_pending_bytes = 256ull << 20;
  uint64_t replica_rebuild_slice_nodes = 0;
  // Scans waiting for the replica are applied together, up to this many voxels (0: one by one).
  uint64_t replica_batch_voxels = uint64_t{1} << 23;
  // ... and only while the update's estimated time stays within this (0: no time bound), so that
  // a query turn waits behind no whole catch-up (daemon/map/map_replica.h).
  double replica_batch_ms = 0;
  unsigned replica_threads = 0;  // its octree stage's threads (0: every hardware thread)
  int replica_nice = 10;         // how much the replica's thread lowers its priority: the octree stage goes first
  // Snapshots, saves and the viewer map read versions of the replica kept per region, no lock
  // held (daemon/map/map_replica.h); false: they copy the replica under its lock, the design
  // before (octomap-rt-bigmap-bench --replica-versions off compares).
  bool replica_versions = true;
  // The depth of the regions those versions are kept in (each written again whole where a scan
  // changed a leaf): finer regions rewrite less of the map per version and cost more entries
  // (docs/ARCHITECTURE.md "Readers and the read replica"); 0: the eviction's depth.
  unsigned replica_version_depth = 0;
  // A version writes only the cells of a region where the replica's octree stage changed a
  // leaf, the rest copied from the region's old records; false: it rewrites every region the
  // scans' keys touched, whole (the design before; octomap-rt-bigmap-bench compares).
  bool replica_version_cells = true;
};

// "" when the memory bound's flags fit together; else why not (a bound or a store bound
// below 1 MiB or past 2^50 bytes, no --map for the store to live beside, a --grid-rate whose
// whole-map grid would bring every spilled region back each period).
std::string memory_bound_problem(const ServerConfig& c);
// "" when `seconds` is a --working-set-seconds the bound can use (0, or in (0, 30 days]).
std::string working_set_problem(double seconds);
// The depth the memory bound evicts at (ServerConfig::evict_depth, 0 resolved).
unsigned evict_region_depth(const ServerConfig& c);
// The depth of the read replica's version regions (ServerConfig::replica_version_depth, 0 resolved).
unsigned replica_version_depth(const ServerConfig& c);

struct ProducerPolicy;
// The producer admission policy (slots, idle release, allow-list) of `c`.
ProducerPolicy producer_policy(const ServerConfig& c);

// Per-producer queue budget sized by memory: 1/64 of physical memory, within [64 MiB, 1 GiB].
uint64_t automatic_queue_budget();

}  // namespace ort::daemon
