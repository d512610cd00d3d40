// `octomap-rt query distance points|box|path`: Euclidean distance to the nearest obstacle
// from a running octomap-rt-server (docs/PROTOCOL.md, "Distance queries"), or from a shard set
// with --shards (the smallest of the shards' distances: shard_client/shard_distance.h): text or
// one JSON document on stdout; a box also as a PNG of one horizontal slice.
#include <cmath>
#include <iostream>
#include <memory>

#include "cli/query/distance_output.h"
#include "cli/query/query_common.h"
#include "query_client/query_args.h"

namespace ort::cli {
namespace {

struct DistanceArgs {
  double max_distance = 2.0;
  bool unknown_occupied = false, gradient = false;
};

void add_distance(CLI::App* cmd, DistanceArgs& d, bool gradient) {
  cmd->add_option("--max", d.max_distance, "clamp [m]: distances stop here, obstacles this far count")
      ->capture_default_str();
  cmd->add_flag("--unknown-occupied", d.unknown_occupied, "unknown space is an obstacle (default: free)");
  if (gradient) cmd->add_flag("--gradient", d.gradient, "also the gradient (central differences)");
}

DistanceRequest request(const DistanceArgs& d, int cell_voxels = 1) {
  DistanceRequest r;
  r.max_distance = d.max_distance;
  r.unknown_occupied = d.unknown_occupied;
  r.gradient = d.gradient;
  r.cell_voxels = cell_voxels;
  return r;
}

void register_points(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("points", "distance (and gradient) of the voxels holding points");
  auto a = std::make_shared<CommonArgs>();
  auto d = std::make_shared<DistanceArgs>();
  auto pts = std::make_shared<std::vector<std::string>>();
  auto file = std::make_shared<std::string>();
  add_common(cmd, *a);
  add_shards_flag(cmd, *a);
  add_distance(cmd, *d, true);
  cmd->add_option("points", *pts, "X,Y,Z points [m]");
  cmd->add_option("--file", *file, "points from a file, three numbers a line");
  cmd->callback([=] {
    std::vector<float> xyz = file->empty() ? std::vector<float>{} : read_points_file(*file);
    const auto more = parse_points(*pts);
    xyz.insert(xyz.end(), more.begin(), more.end());
    if (xyz.empty()) throw CLI::ValidationError("points", "give X,Y,Z points or --file");
    bool partial = false;
    const auto r = a->shards ? routed(connect_shards(*a)->distance_points(xyz, request(*d), shard_wait(*a)), partial)
                             : connect(*a)->distance_points(xyz, request(*d), wait_for(*a));
    if (a->json) write_distance_points_json(std::cout, xyz, r);
    if (refused(r)) std::exit(2);
    if (partial) std::exit(3);
    if (a->json) return;
    for (int i = 0; i < r.num_points; ++i) {
      std::cout << xyz[3 * i] << " " << xyz[3 * i + 1] << " " << xyz[3 * i + 2] << " " << r.distance[i];
      if (r.num_gradient == 3 * r.num_points)
        std::cout << " gradient " << r.gradient[3 * i] << " " << r.gradient[3 * i + 1] << " " << r.gradient[3 * i + 2];
      std::cout << "\n";
    }
  });
}

void register_box(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("box", "the dense distance field of a box (zstd chunks), PNG of a slice");
  auto a = std::make_shared<CommonArgs>();
  auto d = std::make_shared<DistanceArgs>();
  auto box = std::make_shared<std::string>(), png = std::make_shared<std::string>();
  auto cell_voxels = std::make_shared<int>(1);
  auto slice_z = std::make_shared<double>(NAN);
  add_common(cmd, *a);
  add_shards_flag(cmd, *a);
  add_distance(cmd, *d, true);
  cmd->add_option("box", *box, "MINX,MINY,MINZ:MAXX,MAXY,MAXZ [m]")->required();
  cmd->add_option("--cell-voxels", *cell_voxels,
                  "coarser cells of K finest voxels a side (a cell is occupied if any voxel is); 1: the resolution")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--png", *png, "write the horizontal slice at --slice-z as a PNG");
  cmd->add_option("--slice-z", *slice_z, "height of the slice [m] (default: the box's middle)");
  cmd->callback([=] {
    const Box b = parse_box(*box);
    bool partial = false;
    const DistanceBox f =
        a->shards ? routed(connect_shards(*a)->distance_box(b, request(*d, *cell_voxels), shard_wait(*a)), partial)
                  : connect(*a)->distance_box(b, request(*d, *cell_voxels), wait_for(*a));
    if (f.header.status != 0) {
      if (a->json) write_distance_box_json(std::cout, f, "");
      refused(f.header);
      std::exit(2);
    }
    if (!png->empty()) write_distance_slice(f, std::isnan(*slice_z) ? (b.min[2] + b.max[2]) / 2 : *slice_z, *png);
    if (a->json) {
      write_distance_box_json(std::cout, f, *png);
      if (partial) std::exit(3);
      return;
    }
    std::cout << "distance box " << f.nx() << " x " << f.ny() << " x " << f.nz() << " cells of " << f.header.cell_size
              << " m from (" << f.header.origin[0] << ", " << f.header.origin[1] << ", " << f.header.origin[2]
              << "), max " << f.header.max_distance << " m, map state " << f.header.snapshot_id << ", "
              << f.header.num_chunks << " chunks, " << f.header.total_size << " bytes"
              << (png->empty() ? "" : ", slice written to " + *png) << "\n";
    if (partial) std::exit(3);
  });
}

void register_path(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("path", "clearance along a polyline sampled at the map's resolution");
  auto a = std::make_shared<CommonArgs>();
  auto d = std::make_shared<DistanceArgs>();
  auto pts = std::make_shared<std::vector<std::string>>();
  add_common(cmd, *a);
  add_shards_flag(cmd, *a);
  add_distance(cmd, *d, false);
  cmd->add_option("vertices", *pts, "X,Y,Z vertices [m], in order")->required();
  cmd->callback([=] {
    const auto v = parse_points(*pts);
    bool partial = false;
    const auto r = a->shards ? routed(connect_shards(*a)->distance_path(v, request(*d), shard_wait(*a)), partial)
                             : connect(*a)->distance_path(v, request(*d), wait_for(*a));
    if (a->json) write_distance_path_json(std::cout, r);
    if (refused(r)) std::exit(2);
    if (!a->json)
      std::cout << "clearance " << r.min_distance << " m at (" << r.min_xyz[0] << ", " << r.min_xyz[1] << ", "
                << r.min_xyz[2] << "), " << r.min_arc_length << " m along the path (sample " << r.min_sample << " of "
                << r.num_samples << "), map state " << r.snapshot_id << "\n";
    if (partial) std::exit(3);
  });
}

}  // namespace

void register_distance_command(CLI::App& query) {
  auto* cmd = query.add_subcommand("distance", "Euclidean distance to the nearest obstacle: points, a box, a path");
  cmd->require_subcommand(1);
  register_points(*cmd);
  register_box(*cmd);
  register_path(*cmd);
}

}  // namespace ort::cli
