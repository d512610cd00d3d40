#include "daemon/server_cli.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "daemon/long_lived_flags.h"
#include "daemon/queries/distance_flags.h"
#include "daemon/queries/query_answers.h"
#include "daemon/scan_cost_flags.h"
#include "daemon/shard_flags.h"
#include "protocol/channels.h"
#include "protocol/ids.h"
#include "protocol/lcm_url.h"
#include "protocol/limits.h"

namespace ort::daemon {

void add_server_flags(CLI::App& app, ServerFlags& f) {
  app.set_config("--config", "",
                 "read flags from this TOML/INI file (keys: the long flag names; an unknown key is refused)");
  app.allow_config_extras(CLI::config_extras_mode::error);
  app.add_flag("--print-config", f.print_config,
               "print the effective configuration (every key of --config with its value) and exit");
  ort::cli::add_engine_flags(app, f.engine, /*require_resolution=*/false);
  ServerConfig& s = f.server;
  add_map_file_flags(app, f);
  app.add_option("--lcm-url", s.lcm_url,
                 std::string("LCM URL (default: $LCM_DEFAULT_URL, else ") + ort::protocol::kDefaultLcmUrl +
                     "); udpm URLs get recv_buf_size=min(--recv-buf-size, net.core.rmem_max) unless they set it");
  app.add_option(
      "--namespace", f.ns,
      std::string("prefix NS_ for every channel of the protocol, the viewer's OCTOMAP and the reply channels "
                  "included (NS: letters, digits, _), so that servers in different namespaces share one LCM "
                  "URL; default: $") +
          ort::protocol::kNamespaceEnv + ", else none (today's names)");
  app.add_option("--recv-buf-size", s.recv_buf_size, "UDP receive buffer wanted [bytes]")->capture_default_str();
  app.add_option("--scan-channels", s.scan_channels,
                 "regex of scan channels; the part after its literal prefix is the robot id")
      ->capture_default_str();
  app.add_option("--status-channel", s.status.channel, "channel of server_status_t heartbeats")->capture_default_str();
  app.add_option("--status-period", s.status.period_s, "seconds between status messages")->capture_default_str();
  app.add_option("--octomap-raw-rate", s.octomap_raw.rate_hz,
                 "publish the map as octomap.raw_t (LCM's OctoMap viewers) at this rate [Hz]; 0: off")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--octomap-raw-channel", s.octomap_raw.channel, "channel of octomap.raw_t")->capture_default_str();
  app.add_option("--occupancy-min-z,--occupancy_min_z", s.octomap_raw.occupancy_min_z,
                 "the OCTOMAP map shows occupied cells only above this z [m] (octomap_server's occupancy_min_z; the "
                 "map of record keeps them; the 2D grid's band is --grid-z)");
  app.add_option("--occupancy-max-z,--occupancy_max_z", s.octomap_raw.occupancy_max_z,
                 "... and only below this z [m] (octomap_server's occupancy_max_z)");
  app.add_option("--octomap-raw-max-kib", f.octomap_raw_max_kib,
                 "size cap of one octomap.raw_t [KiB]; a larger map is sent depth-limited, or not at all (said in "
                 "the status); default: 90 % of net.core.rmem_default");
  app.add_flag("--no-pipeline", f.no_pipeline, "run the GPU and CPU stages on one thread, one scan after another");
  app.add_flag("--no-read-replica", f.no_read_replica,
               "whole-map readers (snapshots, saves, the OCTOMAP viewer map, status counts) copy the map under its "
               "lock instead of reading the read replica (which costs one more tree in memory and a second octree "
               "update per scan on another thread, and never holds mapping up)");
  app.add_option(
         "--warm-up-points", s.warm_up_points,
         "points of the synthetic scan shot and applied to a scratch tree at start-up, so the first scans "
         "pay no one-time costs (buffers sized, threads started); at most --max-points; the map is untouched; 0: "
         "no warm-up")
      ->capture_default_str();
  app.add_option("--server-id", s.server_id, "name in status messages (default octomap-rt-server@HOST)");
  app.add_option("--queue-mib", f.queue_mib,
                 "per-producer queue budget [MiB]; 0: 1/64 of physical memory within [64, 1024]")
      ->capture_default_str();
  app.add_option("--max-points", s.max_points, "largest scan accepted [points]")->capture_default_str();
  app.add_option("--control-token", s.queries.control_token,
                 "allow map edits (octomap-rt map clear-box/reset) signed with this secret (an HMAC of each edit; "
                 "the token itself never goes on the network); at least 16 characters; without it every edit is "
                 "refused");
  app.add_option("--edit-window", s.queries.edit_window_s,
                 "seconds an edit's utime may differ from the server's clock (older ones are refused as stale; "
                 "nonces are remembered this long against replays)")
      ->capture_default_str();
  app.add_option("--max-edit-nodes", s.queries.edit_bounds.max_new_nodes,
                 "a map edit that would add more nodes is refused before it starts (the map's exclusive lock "
                 "holds mapping while an edit runs)")
      ->capture_default_str();
  app.add_option("--max-edit-work", s.queries.edit_bounds.max_work,
                 "a map edit that would visit, make or free more nodes is refused before it starts")
      ->capture_default_str();
  app.add_option("--query-queue", s.queries.per_client_queue, "queued queries per client; more get BUSY replies")
      ->capture_default_str();
  add_grid_flags(app, s.queries.grid);
  add_point_filter_flags(app, s.point_filters);
  add_shard_flags(app, f.shard);
  app.add_option("--query-max-work", s.queries.bounds.max_work,
                 "most nodes a query may visit or key steps its rays may walk; past it a ray or box query "
                 "is cut (its reply says where), a region or grid refused")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t{1}, std::numeric_limits<uint64_t>::max()));
  app.add_option("--query-lock-ms", s.queries.bounds.lock_ms,
                 "longest one query may hold the map's read lock [ms]; past it the query is cut as above")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 10000.0));
  app.add_option("--query-max-reply-bytes", s.queries.bounds.max_reply_bytes,
                 "most bytes of replies one region or grid query may make the server send")
      ->capture_default_str()
      ->check(CLI::Range(size_t{1024}, size_t{1} << 30));
  app.add_option("--query-chunk-interval-ms", s.queries.reply_chunk_interval_ms,
                 "pause between two messages of one query's reply (pacing for clients' receive buffers; 0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  add_distance_flags(app, s.queries.distance);
  app.add_option("--latency-bound", s.latency_bound_s,
                 "overload bound [s]: a scan queued longer is dropped ('over latency bound') and the status is "
                 "DEGRADED while the end-to-end p99 exceeds it; 0: never drop for age")
      ->capture_default_str();
  app.add_option("--snapshot-zstd-level", s.serving.snapshots.zstd_level,
                 "zstd level of served snapshots (0: uncompressed)")
      ->capture_default_str();
  app.add_option("--snapshots-kept", s.serving.snapshots.kept, "snapshots kept for re-sends")->capture_default_str();
  app.add_option("--snapshot-min-interval", s.serving.snapshots.min_interval_s,
                 "seconds between two new snapshots, however many clients ask")
      ->capture_default_str();
  app.add_option("--fresh-snapshot-interval", s.serving.fresh_interval_s,
                 "seconds between two new snapshots for fresh requests (snapshot_id -1): every fresh request "
                 "waiting gets the next one, so a flood of them copies the map at most this often")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--map-request-queue", s.serving.request_queue,
                 "map requests waiting, all clients; more are refused as busy (with a retry time)")
      ->capture_default_str()
      ->check(CLI::Range(size_t{1}, size_t{65536}));
  app.add_option("--map-requests-per-client", s.serving.requests_per_client,
                 "map requests of one client waiting; more are refused as busy (one client cannot fill the queue)")
      ->capture_default_str()
      ->check(CLI::Range(size_t{1}, size_t{1024}));
  app.add_option("--chunk-interval-ms", s.serving.chunk_interval_ms,
                 "pause between two snapshot chunks or delta parts (pacing for clients' receive buffers)")
      ->capture_default_str();
  app.add_option("--delta-rate", s.deltas.max_rate_hz, "most map deltas a second (changes coalesced); 0: no deltas")
      ->capture_default_str();
  app.add_option("--map-request-channel", s.serving.request_channel, "channel of map requests")->capture_default_str();
  app.add_option("--map-info-channel", s.serving.info_channel, "channel of map_info_t")->capture_default_str();
  app.add_option("--map-delta-channel", s.deltas.channel, "channel of map deltas")->capture_default_str();
  app.add_flag("--delta-exact", s.deltas.exact,
               "deltas carry every changed leaf with its log-odds (an exact mirror), not only class changes");
  app.add_option("--drain-timeout", s.drain_timeout_s,
                 "at SIGTERM/SIGINT, apply queued scans for at most this long [s]; the rest are dropped ('left at "
                 "shutdown') and the map as applied is saved")
      ->capture_default_str();
  app.add_option("--stuck-stage", s.stuck_stage_s, "DEGRADED when a pipeline stage is on one scan longer than this [s]")
      ->capture_default_str();
  add_long_lived_flags(app, s);
  app.add_option("--max-scan-work", f.max_scan_work,
                 "most ray-walk steps one scan may cost (summed over its windows); a scan above it is rejected "
                 "as 'too much work'; 0: no limit")
      ->capture_default_str();
  add_scan_cost_flags(app, s.scan_costs);
  app.add_option("--max-producers", s.max_producers,
                 "most scan channels served at once; more are rejected (too many producers) unless an idle "
                 "one can be let go (--producer-idle-release)")
      ->capture_default_str();
  app.add_option("--producer-idle-release", s.producer_idle_release_s,
                 "seconds without a message after which a producer's slot may go to a new robot; 0: never")
      ->capture_default_str();
  app.add_option("--allow-robot", s.allowed_robots,
                 "accept scans only from this robot id (repeatable; case-insensitive); default: any robot. "
                 "Not authentication: LCM has none (see docs/RELIABILITY.md)");
}

// Every channel of `c` (today's names, or the ones given by flag) as NS_ + the name, each checked
// against LCM's 63 characters: a server that could not publish or hear one does not start.
void apply_namespace(ServerConfig& c, const std::string& ns) {
  try {
    (void)protocol::channels_in(ns);  // the rule: NS's characters, the fixed names' lengths
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--namespace", e.what());
  }
  c.ns = ns;
  for (std::string* channel :
       {&c.status.channel, &c.serving.request_channel, &c.serving.info_channel, &c.deltas.channel,
        &c.serving.reply_prefix, &c.octomap_raw.channel, &c.queries.points_channel, &c.queries.rays_channel,
        &c.queries.boxes_channel, &c.queries.grid_channel, &c.queries.distance_channel, &c.queries.edit_channel,
        &c.queries.grid.channel}) {
    *channel = protocol::in_namespace(ns, *channel);
    if (const std::string why = protocol::check_channel_length(*channel); !why.empty())
      throw CLI::ValidationError("--namespace", why);
  }
  c.scan_channels = protocol::in_namespace(ns, c.scan_channels);
  c.queries.status_channel = c.status.channel;
  c.queries.scan_prefix = protocol::in_namespace(ns, protocol::kScanChannelPrefix);
}

namespace {

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string nearest_option(const CLI::App& app, const std::string& key) {
  std::string best;
  size_t best_distance = SIZE_MAX;
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& name : o->get_lnames()) {
      const size_t d = edit_distance(key, name);
      if (d < best_distance) best_distance = d, best = name;
    }
  }
  return best;
}

std::string parse_server_flags(CLI::App& app, int argc, const char* const* argv) {
  static const std::string kExtras = "INI was not able to parse ";
  try {
    app.parse(argc, argv);
  } catch (const CLI::ConfigError& e) {
    const std::string what = e.what();
    if (what.rfind(kExtras, 0) != 0) return what;
    const std::string key = what.substr(kExtras.size());
    return "--config: unknown key '" + key + "' (did you mean '" + nearest_option(app, key) + "'?)";
  }
  return "";
}

// An option left at a default that has no text (the filters' open limits, empty strings) is left out: read
// back, it takes the same built-in default, where `key=""` would be read as the number 0.
std::string effective_config(const CLI::App& app) {
  std::istringstream in(app.config_to_str(/*default_also=*/true, false));
  std::string out, line;
  while (std::getline(in, line)) {
    const size_t eq = line.find('=');
    if (eq != std::string::npos && line.compare(eq, std::string::npos, "=\"\"") == 0) {
      const CLI::Option* given = app.get_option_no_throw("--" + line.substr(0, eq));
      if (given == nullptr || given->count() == 0) continue;
    }
    out += line + "\n";
  }
  return out;
}

ServerConfig to_server_config(const ServerFlags& f) {
  ServerConfig c = f.server;
  const std::string ns = protocol::namespace_from(f.ns);
  c.engine = ort::cli::to_engine_options(f.engine);
  c.resolution_from_file = f.resolution && f.resolution->count() == 0;
  if (c.resolution_from_file && !f.shard.boxes.empty())
    throw CLI::ValidationError("--shard-box", "needs -r: the boxes are cut into regions at the map's resolution");
  c.shard = to_shard_set(f.shard, c.engine.resolution);
  apply_namespace(c, c.shard.sharded() ? protocol::shard_namespace(ns, c.shard.index) : ns);
  if (c.shard.sharded()) keep_shared_channels(c, f.server, ns);
  c.pipeline = !f.no_pipeline;
  c.read_replica = !f.no_read_replica;
  // Stage 1 shoots beside stage 2's octree update: the octree stage leaves it a core (a
  // worker preempted by stage 1 stalls every join of the update), and the voxel list of a
  // scan, small here, comes straight into host memory (one fence wait less a scan).
  c.engine.shoots_beside_apply = c.pipeline;
  // ... and, in a daemon, more: its LCM thread receives and decodes the scans (300 RGB-D
  // scans/s = 930 MB/s) beside the kernel's network work: on the H200, 12 octree workers
  // instead of 15 shortened stage 2's p99 and the end-to-end p99 (docs/history/benchmarks-log.md,
  // the fourth session's daemon).
  c.engine.spare_threads = 4;
  c.engine.backend.compact_into_host_memory = true;
  c.engine.max_scan_walk_keys = f.max_scan_work;
  if (!(f.queue_mib >= 0 && f.queue_mib <= 1e9)) throw CLI::ValidationError("--queue-mib", "must be a number >= 0");
  c.queue_budget_bytes = static_cast<uint64_t>(f.queue_mib * 1048576.0);
  if (f.octomap_raw_max_kib < 0) throw CLI::ValidationError("--octomap-raw-max-kib", "must be >= 0");
  if (std::isnan(c.octomap_raw.occupancy_min_z) || std::isnan(c.octomap_raw.occupancy_max_z) ||
      !(c.octomap_raw.occupancy_min_z < c.octomap_raw.occupancy_max_z))
    throw CLI::ValidationError("--occupancy-min-z/--occupancy-max-z", "must be numbers with min < max");
  c.octomap_raw.max_bytes = static_cast<size_t>(f.octomap_raw_max_kib * 1024.0);
  if (!(c.status.period_s > 0 && c.status.period_s < 1e6))
    throw CLI::ValidationError("--status-period", "must be a number of seconds > 0");
  if (!std::isfinite(c.save_interval_s))
    throw CLI::ValidationError("--save-interval", "must be a finite number of seconds");
  if (c.max_points == 0) throw CLI::ValidationError("--max-points", "must be > 0");
  if (c.max_producers == 0) throw CLI::ValidationError("--max-producers", "must be > 0");
  if (c.serving.snapshots.zstd_level < 0 || c.serving.snapshots.zstd_level > 19)
    throw CLI::ValidationError("--snapshot-zstd-level", "must be within 0..19");
  if (c.serving.snapshots.kept == 0) throw CLI::ValidationError("--snapshots-kept", "must be > 0");
  if (!(c.serving.chunk_interval_ms >= 0)) throw CLI::ValidationError("--chunk-interval-ms", "must be >= 0");
  if (const std::string bad = check_point_filters(c.point_filters); !bad.empty())
    throw CLI::ValidationError("--pointcloud-*/--sensor-*/--min-range", bad);
  // A rate of 0 (the default, also as --print-config writes it) needs no band; a rate above 0 does.
  if (c.queries.grid.rate_hz > 0 && !c.queries.grid.z_given)
    throw CLI::ValidationError("--grid-rate", "requires --grid-z");
  if (c.queries.grid.rate_hz > 0) {  // the rule of grid queries (daemon/query_answers)
    octomap_rt::grid_query_t q{};
    q.z_min = c.queries.grid.z_min, q.z_max = c.queries.grid.z_max, q.cell_size = c.queries.grid.cell_size;
    if (const std::string bad = validate_query(QueryMessage(q), c.engine.resolution); !bad.empty())
      throw CLI::ValidationError("--grid-z/--grid-cell", bad);
  }
  for (const auto& [value, name] :
       {std::pair{c.latency_bound_s, "--latency-bound"}, std::pair{c.drain_timeout_s, "--drain-timeout"},
        std::pair{c.stuck_stage_s, "--stuck-stage"}})
    if (!(value >= 0 && value <= 1e6)) throw CLI::ValidationError(name, "must be a number of seconds in [0, 1e6]");
  check_long_lived_flags(c);
  if (!c.queries.control_token.empty() && c.queries.control_token.size() < 16)
    throw CLI::ValidationError("--control-token",
                               "must have at least 16 characters: one observed edit lets anyone test guesses of it "
                               "offline");
  if (!(c.queries.edit_window_s >= 1 && c.queries.edit_window_s <= 3600))
    throw CLI::ValidationError("--edit-window", "must be a number of seconds in [1, 3600]");
  for (const auto& [value, name] : {std::pair{c.queries.edit_bounds.max_new_nodes, "--max-edit-nodes"},
                                    std::pair{c.queries.edit_bounds.max_work, "--max-edit-work"}})
    if (value < 1 || value > int64_t(1) << 40) throw CLI::ValidationError(name, "must be within 1..2^40");
  if (!std::isfinite(c.producer_idle_release_s))
    throw CLI::ValidationError("--producer-idle-release", "must be a finite number of seconds");
  for (const std::string& id : c.allowed_robots)
    if (!protocol::valid_robot_id(id))
      throw CLI::ValidationError(
          "--allow-robot",
          "'" + id + "' is not a robot id (1-" + std::to_string(protocol::kMaxRobotIdLength) + " of [A-Za-z0-9_-])");
  try {
    std::regex check(c.scan_channels);
  } catch (const std::regex_error& e) {
    throw CLI::ValidationError("--scan-channels", std::string("not a regular expression: ") + e.what());
  }
  if (!c.map_path.empty() && (c.map_path.size() < 4 || c.map_path.compare(c.map_path.size() - 3, 3, ".ot") != 0))
    throw CLI::ValidationError("--map",
                               "must name an .ot file (OctoMap's full format keeps the log-odds; a .bt map "
                               "can be the --prior of a new --map)");
  auto ends_with = [](const std::string& s, const char* e) {
    const size_t n = std::strlen(e);
    return s.size() >= n && s.compare(s.size() - n, n, e) == 0;
  };
  if (!c.prior_path.empty() && !ends_with(c.prior_path, ".bt") && !ends_with(c.prior_path, ".ot"))
    throw CLI::ValidationError("--prior", "must name a .bt or .ot file");
  return c;
}

}  // namespace ort::daemon
