// `octomap-rt map get|info|watch`: the map service's client side on the command line.
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/map_commands.h"
#include "cli/namespace_flag.h"
#include "cli/progress_bar.h"
#include "cli/shard_commands.h"
#include "map_client/map_client.h"
#include "protocol/lcm_url.h"

namespace ort::cli {
namespace {

using Chunk = octomap_rt::map_chunk_t;

int8_t format_of(const std::string& path) {
  auto ends = [&](const char* ext) { return path.size() > 3 && path.compare(path.size() - 3, 3, ext) == 0; };
  if (ends(".bt")) return Chunk::FORMAT_OCTOMAP_BINARY;
  if (ends(".ot")) return Chunk::FORMAT_OCTOMAP_FULL;
  throw CLI::ValidationError("-o", "must end in .bt (OctoMap binary) or .ot (full, with log-odds)");
}

void run_get(const MapArgs& a, const std::string& out_path) {
  const int8_t format = format_of(out_path);
  client::MapClient c(ort::protocol::lcm_url_or_default(a.lcm_url),
                      client::ClientOptions{}.in_namespace(protocol::namespace_from(a.ns)));
  std::unique_ptr<ProgressBar> bar;
  auto progress = [&](int64_t got, int64_t total) {
    if (a.quiet || a.json) return;
    if (!bar) bar = std::make_unique<ProgressBar>("map get", static_cast<size_t>(total), true);
    bar->update(static_cast<size_t>(got), std::to_string(got / 1024) + " KiB");
  };
  const client::FetchedSnapshot s = c.fetch_snapshot(format, a.timeout_s, progress);
  if (bar) bar->finish();
  std::ofstream f(out_path, std::ios::binary);
  f.write(s.bytes.data(), static_cast<std::streamsize>(s.bytes.size()));
  if (!f) throw std::runtime_error("cannot write '" + out_path + "'");
  if (a.json) {
    std::cout << "{\"snapshot_id\": " << s.snapshot_id << ", \"scans\": " << s.num_scans
              << ", \"raw_bytes\": " << s.bytes.size() << ", \"compressed_bytes\": " << s.compressed_size
              << ", \"chunks\": " << s.num_chunks << ", \"requests\": " << s.requests << ", \"seconds\": " << s.seconds
              << ", \"file\": \"" << out_path << "\"}\n";
  } else {
    std::printf("snapshot %lld (%lld scans): %zu bytes raw, %lld compressed, %d chunks, %d request(s), %.3f s -> %s\n",
                (long long)s.snapshot_id, (long long)s.num_scans, s.bytes.size(), (long long)s.compressed_size,
                s.num_chunks, s.requests, s.seconds, out_path.c_str());
  }
}

void run_info(const MapArgs& a) {
  client::MapClient c(ort::protocol::lcm_url_or_default(a.lcm_url),
                      client::ClientOptions{}.in_namespace(protocol::namespace_from(a.ns)));
  const auto m = c.wait_info(a.timeout_s);
  if (!m)
    throw std::runtime_error("no map_info_t within " + std::to_string(a.timeout_s) + " s (is the server running?)");
  if (a.json) {
    std::cout << "{\"server_id\": \"" << m->server_id << "\", \"map_epoch\": " << m->map_epoch
              << ", \"map_version\": " << m->map_version << ", \"snapshot_id\": " << m->snapshot_id
              << ", \"num_scans\": " << m->num_scans << ", \"delta_seq\": " << m->delta_seq
              << ", \"resolution\": " << m->resolution << ", \"uncompressed_size\": " << m->uncompressed_size
              << ", \"total_size\": " << m->total_size << ", \"num_chunks\": " << m->num_chunks << ", \"bbox_min\": ["
              << m->bbox_min[0] << ", " << m->bbox_min[1] << ", " << m->bbox_min[2] << "], \"bbox_max\": ["
              << m->bbox_max[0] << ", " << m->bbox_max[1] << ", " << m->bbox_max[2] << "]}\n";
    return;
  }
  std::printf("server %s: map version %lld of epoch %llx, resolution %g m, last delta seq %lld\n", m->server_id.c_str(),
              (long long)m->map_version, (unsigned long long)m->map_epoch, m->resolution, (long long)m->delta_seq);
  std::printf("latest snapshot %lld (%lld scans): %lld bytes raw, %lld compressed (%s), %d chunks\n",
              (long long)m->snapshot_id, (long long)m->num_scans, (long long)m->uncompressed_size,
              (long long)m->total_size, m->format == Chunk::FORMAT_OCTOMAP_BINARY ? ".bt" : ".ot", m->num_chunks);
  std::printf("bbox [%.2f %.2f %.2f] .. [%.2f %.2f %.2f] m; region [%.0f %.0f %.0f] .. [%.0f %.0f %.0f] m\n",
              m->bbox_min[0], m->bbox_min[1], m->bbox_min[2], m->bbox_max[0], m->bbox_max[1], m->bbox_max[2],
              m->region_min[0], m->region_min[1], m->region_min[2], m->region_max[0], m->region_max[1],
              m->region_max[2]);
  for (int i = 0; i < m->num_producers; ++i)
    std::printf("  producer %-16s last seq %lld\n", m->producer_id[i].c_str(), (long long)m->producer_last_seq[i]);
}

void add_common(CLI::App* cmd, MapArgs& a) {
  cmd->add_option("--lcm-url", a.lcm_url,
                  std::string("LCM URL (default: $LCM_DEFAULT_URL, else ") + ort::protocol::kDefaultLcmUrl + ")");
  add_namespace_flag(cmd, a.ns);
  cmd->add_option("--timeout", a.timeout_s, "seconds to wait for the server")->capture_default_str();
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  cmd->add_flag("-q,--quiet", a.quiet, "no progress output");
}

}  // namespace

void register_map_command(CLI::App& app) {
  auto args = std::make_shared<MapArgs>();
  auto out = std::make_shared<std::string>();
  CLI::App* map = app.add_subcommand("map", "get the map from octomap-rt-server: snapshots, info, live deltas");
  map->require_subcommand(1);
  add_map_edit_commands(map);  // clear-box, reset (map_edit_command.cpp)
  CLI::App* get = map->add_subcommand("get", "fetch a snapshot of the server's map into a .bt or .ot file");
  get->add_option("-o,--output", *out, "FILE.bt or FILE.ot")->required();
  add_common(get, *args);
  get->add_flag("--shards", args->shards,
                "the namespace is a shard set (octomap-rt-server --shard): find the shards by their statuses, fetch "
                "each one's map and merge them into one (each shard's snapshot id and scans are printed)");
  get->add_flag("--partial", args->partial, "with --shards: write the merged map even when a shard is missing");
  get->callback([args, out] {
    if (!args->shards) return run_get(*args, *out);
    if (const int rc = run_get_shards(*args, *out, args->partial); rc != 0) throw CLI::RuntimeError(rc);
  });
  CLI::App* info = map->add_subcommand("info", "print the server's next map_info_t");
  add_common(info, *args);
  info->callback([args] { run_info(*args); });
  CLI::App* watch =
      map->add_subcommand("watch", "mirror the map (snapshot + deltas); print delta rate, bandwidth, classes");
  add_common(watch, *args);
  watch->add_option("--seconds", args->seconds, "stop after this long; 0: at Ctrl-C")->capture_default_str();
  watch->add_option("--save", args->save, "write the mirror to this .ot file at the end");
  watch->add_flag("--shards", args->shards,
                  "the namespace is a shard set: follow every shard's deltas in one mirror (each shard's version and "
                  "epoch printed, a missing or late shard named; exit status 3 if one is at the end)");
  watch->callback([args] {
    if (const int rc = run_map_watch(*args); rc != 0) throw CLI::RuntimeError(rc);
  });
  auto files = std::make_shared<std::vector<std::string>>();
  CLI::App* diff = map->add_subcommand(
      "diff", "compare two maps (.ot/.bt) voxel by voxel: class, and log-odds; exit 1 if classes differ");
  diff->add_option("A B", *files, "two map files")->required()->expected(2);
  diff->callback([files] {
    if (run_map_diff((*files)[0], (*files)[1]) != 0) throw CLI::RuntimeError(1);
  });
}

}  // namespace ort::cli
