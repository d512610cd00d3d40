// `octomap-rt query points|rays|box|grid|distance`: ask a running octomap-rt-server about its map
// (the query service, docs/ARCHITECTURE.md "Queries"); text or one JSON document on stdout.
#include <unistd.h>

#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/grid_picture.h"
#include "cli/namespace_flag.h"
#include "cli/query/query_common.h"
#include "cli/shard_commands.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/box_reply_t.hpp"
#include "protocol/lcm_url.h"
#include "query_client/query_args.h"
#include "query_client/query_client.h"
#include "query_client/query_json.h"

namespace ort::cli {

void add_shards_flag(CLI::App* cmd, CommonArgs& a) {
  cmd->add_flag("--shards", a.shards,
                "the namespace is a shard set (octomap-rt-server --shard): route by region, say which shard did "
                "not answer (exit status 3); --wait-robot waits on every shard asked; no --min-snapshot (each shard "
                "has its own map states)");
}

std::unique_ptr<ShardQueries> connect_shards(const CommonArgs& a) {
  if (a.min_snapshot != 0)
    throw CLI::ValidationError("--shards", "does not wait for a map state (each shard has its own; --wait-robot does)");
  const std::string url = ort::protocol::lcm_url_or_default(a.lcm_url), ns = protocol::namespace_from(a.ns);
  const ShardRoster roster = find_shards_for_query(url, ns, a.timeout_s);
  const std::string id = a.client_id.empty() ? "cli-" + std::to_string(::getpid()) : a.client_id;
  return std::make_unique<ShardQueries>(url, id, std::chrono::milliseconds(static_cast<int64_t>(a.timeout_s * 1000)),
                                        ns, *roster.set(), roster.resolution());
}

namespace {

using namespace ort::client;

// The flags every subcommand here shares, and --shards.
void add_query_flags(CLI::App* cmd, CommonArgs& a) {
  add_common(cmd, a);
  add_shards_flag(cmd, a);
}

void register_points(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("points", "occupancy of points: unknown / free / occupied and probability");
  auto a = std::make_shared<CommonArgs>();
  auto pts = std::make_shared<std::vector<std::string>>();
  auto file = std::make_shared<std::string>();
  auto depth = std::make_shared<int>(0);
  add_query_flags(cmd, *a);
  cmd->add_option("points", *pts, "X,Y,Z points [m]");
  cmd->add_option("--file", *file, "points from a file, three numbers a line");
  cmd->add_option("--depth", *depth, "OctoMap search depth 1..16; 0: finest")->capture_default_str();
  cmd->callback([=] {
    std::vector<float> xyz = file->empty() ? parse_points(*pts) : read_points_file(*file);
    if (!file->empty()) {
      const auto more = parse_points(*pts);
      xyz.insert(xyz.end(), more.begin(), more.end());
    }
    if (xyz.empty()) throw CLI::ValidationError("points", "give X,Y,Z points or --file");
    bool partial = false;
    const auto r = a->shards ? routed(connect_shards(*a)->points(xyz, *depth, shard_wait(*a)), partial)
                             : connect(*a)->points(xyz, *depth, wait_for(*a));
    if (a->json) write_points_json(std::cout, xyz, r);
    if (refused(r)) std::exit(2);
    if (partial) std::exit(3);
    if (!a->json)
      for (int i = 0; i < r.num_results; ++i)
        std::cout << xyz[3 * i] << " " << xyz[3 * i + 1] << " " << xyz[3 * i + 2] << " " << state_name(r.occupancy[i])
                  << " " << r.probability[i] << "\n";
  });
}

void register_rays(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("rays", "cast rays as OcTree::castRay does: hit, end point, end voxel's state");
  auto a = std::make_shared<CommonArgs>();
  auto rays = std::make_shared<std::vector<std::string>>();
  auto max_range = std::make_shared<float>(-1.f);
  auto ignore = std::make_shared<bool>(false);
  add_query_flags(cmd, *a);
  cmd->add_option("rays", *rays, "OX,OY,OZ:DX,DY,DZ (origin : direction)")->required();
  cmd->add_option("--max-range", *max_range, "[m]; <= 0: none")->capture_default_str();
  cmd->add_flag("--ignore-unknown", *ignore, "pass through unknown voxels (needs --max-range)");
  cmd->callback([=] {
    std::vector<float> o, d;
    for (const std::string& s : *rays) {
      const Box b = parse_box(s);
      o.insert(o.end(), {float(b.min[0]), float(b.min[1]), float(b.min[2])});
      d.insert(d.end(), {float(b.max[0]), float(b.max[1]), float(b.max[2])});
    }
    bool partial = false;
    const auto r = a->shards ? routed(connect_shards(*a)->rays(o, d, *max_range, *ignore, shard_wait(*a)), partial)
                             : connect(*a)->rays(o, d, *max_range, *ignore, wait_for(*a));
    if (a->json) write_rays_json(std::cout, r);
    if (refused(r)) std::exit(2);
    if (partial) std::exit(3);
    if (!a->json)
      for (int i = 0; i < r.num_rays; ++i)
        std::cout << (r.hit[i] ? "hit " : "no hit ") << r.end_xyz[3 * i] << " " << r.end_xyz[3 * i + 1] << " "
                  << r.end_xyz[3 * i + 2] << " " << state_name(r.end_state[i]) << "\n";
  });
}

// A box reply as JSON or one line a box; exit status 2 when it was refused.
void print_boxes(const octomap_rt::box_reply_t& r, bool json) {
  if (json) write_boxes_json(std::cout, r);
  if (refused(r)) std::exit(2);
  if (!json)
    for (int i = 0; i < r.num_boxes; ++i)
      std::cout << "occupied " << r.occupied[i] << " free " << r.free[i] << " unknown " << r.unknown[i]
                << (r.any_occupied[i] ? " (occupied)" : " (clear)") << "\n";
}

// A region's nodes, a line each, or JSON; exit status 2 when refused.
void print_region(const std::vector<octomap_rt::region_chunk_t>& chunks, bool json) {
  if (json) write_region_json(std::cout, chunks);
  if (refused(chunks.front())) std::exit(2);
  if (!json)
    for (const auto& c : chunks)
      for (int i = 0; i < c.num_voxels; ++i)
        std::cout << c.center_xyz[3 * i] << " " << c.center_xyz[3 * i + 1] << " " << c.center_xyz[3 * i + 2]
                  << " depth " << int(c.depth[i]) << " " << state_name(c.state[i]) << "\n";
}

void register_box(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("box", "finest-voxel counts of boxes (or a region's nodes with --region)");
  auto a = std::make_shared<CommonArgs>();
  auto boxes = std::make_shared<std::vector<std::string>>();
  auto any = std::make_shared<bool>(false), region = std::make_shared<bool>(false),
       free = std::make_shared<bool>(false);
  auto depth = std::make_shared<int>(0);
  add_query_flags(cmd, *a);
  cmd->add_option("boxes", *boxes, "MINX,MINY,MINZ:MAXX,MAXY,MAXZ [m]")->required();
  cmd->add_flag("--any", *any, "only whether any voxel is occupied (stops at the first)");
  cmd->add_flag("--region", *region, "list the box's occupied nodes (one box)");
  cmd->add_flag("--include-free", *free, "with --region: also the free nodes");
  cmd->add_option("--depth", *depth, "with --region: node depth 1..16; 0: finest");
  cmd->callback([=] {
    std::vector<Box> bs;
    for (const std::string& s : *boxes) bs.push_back(parse_box(s));
    if (*region && bs.size() != 1) throw CLI::ValidationError("--region", "takes exactly one box");
    if (a->shards) {
      bool partial = false;
      if (*region) {
        const auto r = routed(connect_shards(*a)->region(bs[0], *depth, *free, shard_wait(*a)), partial);
        print_region({r}, a->json);
        if (partial) std::exit(3);
        return;
      }
      const int8_t mode = *any ? octomap_rt::box_query_t::MODE_ANY_OCCUPIED : octomap_rt::box_query_t::MODE_COUNTS;
      const auto r = routed(connect_shards(*a)->boxes(bs, mode, shard_wait(*a)), partial);
      print_boxes(r, a->json);
      if (partial) std::exit(3);
      return;
    }
    auto client = connect(*a);
    if (*region) {
      print_region(client->region(bs[0], *depth, *free, wait_for(*a)), a->json);
      return;
    }
    const int8_t mode = *any ? octomap_rt::box_query_t::MODE_ANY_OCCUPIED : octomap_rt::box_query_t::MODE_COUNTS;
    const auto r = client->boxes(bs, mode, wait_for(*a));
    print_boxes(r, a->json);
  });
}

void register_grid(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("grid", "2D grid of a z band (occupied if any voxel is): PNG and/or JSON");
  auto a = std::make_shared<CommonArgs>();
  auto z = std::make_shared<std::string>(), window = std::make_shared<std::string>(),
       out = std::make_shared<std::string>();
  auto cell = std::make_shared<double>(0);
  add_query_flags(cmd, *a);
  cmd->add_option("--z", *z, "z band MIN:MAX [m]")->required();
  cmd->add_option("--cell", *cell, "cell size [m], a multiple of the resolution; 0: the resolution");
  cmd->add_option("--window", *window, "X0,Y0:X1,Y1 [m] (default: the map's extent)");
  cmd->add_option("-o,--output", *out, "PNG file to write");
  cmd->callback([=] {
    double z0, z1;
    parse_range(*z, z0, z1);
    Box w{};
    if (!window->empty()) {
      const size_t colon = window->find(':');
      const auto lo = parse_numbers(window->substr(0, colon), 2), hi = parse_numbers(window->substr(colon + 1), 2);
      w = Box{{lo[0], lo[1], 0}, {hi[0], hi[1], 0}};
    }
    bool partial = false;
    const Box* win = window->empty() ? nullptr : &w;
    const Grid g = a->shards ? routed(connect_shards(*a)->grid(z0, z1, *cell, win, shard_wait(*a)), partial)
                             : connect(*a)->grid(z0, z1, *cell, win, wait_for(*a));
    if (refused(g.header)) {
      if (a->json) write_grid_json(std::cout, g, "");
      std::exit(2);
    }
    if (!out->empty()) write_grid_png(g, *out);
    if (a->json)
      write_grid_json(std::cout, g, *out);
    else
      std::cout << "grid " << g.header.width << " x " << g.header.height << " cells of " << g.header.cell_size
                << " m from (" << g.header.origin_x << ", " << g.header.origin_y << "), map state "
                << g.header.snapshot_id << (out->empty() ? "" : ", written to " + *out) << "\n";
    if (partial) std::exit(3);
  });
}

}  // namespace

void register_query_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("query", "ask a running octomap-rt-server about its map");
  cmd->require_subcommand(1);
  register_points(*cmd);
  register_rays(*cmd);
  register_box(*cmd);
  register_grid(*cmd);
  register_distance_command(*cmd);
}

}  // namespace ort::cli
