#include "engine/map_engine.h"

#include <vector>

#include "core/clock.h"
#include "core/map_frame.h"

namespace ort {

MapEngine::MapEngine(const EngineOptions& opts, const Log& log) : opts_(opts), octree_stage_(opts.octree) {
  opts_.backend.resolution = opts.resolution;
  opts_.backend.max_range = opts.max_range;
  opts_.backend.traversal = opts.traversal;
  backend_ = make_backend(opts_.backend, log);
}

std::unique_ptr<octomap::OcTree> MapEngine::make_tree() const {
  auto tree = std::make_unique<octomap::OcTree>(opts_.resolution);
  apply_sensor_model(*tree, opts_.sensor);
  return tree;
}

void MapEngine::shoot(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range,
                      ShotScan& out) {
  out = ShotScan{};
  const auto t0 = SteadyClock::now();
  const RayBatch batch = prepare_scan(origin, points, max_range, opts_.resolution, out.prepare, opts_.octree.threads);
  out.shoot.times.prepare_ms = ms_since(t0);
  if (!out.prepare.origin_ok) return;
  backend_->shoot(batch, opts_.traversal, out.voxels, out.shoot);
  count_states(out);
}

void MapEngine::shoot_posed(const octomap::pose6d& pose, const octomap::point3d& origin,
                            std::span<const octomap::point3d> sensor_points, double max_range, ShotScan& out) {
  if (backend_->prepares_on_device()) {
    out = ShotScan{};
    backend_->shoot_posed({&pose, origin, sensor_points, max_range}, opts_.traversal, out.voxels, out.shoot,
                          out.prepare);
    count_states(out);
    return;
  }
  const auto t0 = SteadyClock::now();
  std::vector<octomap::point3d> world(sensor_points.begin(), sensor_points.end());
  transform_to_map_frame(world, pose, opts_.octree.threads);
  const double transform_ms = ms_since(t0);
  shoot(origin, world, max_range, out);
  out.shoot.times.prepare_ms += transform_ms;
}

void MapEngine::count_states(ShotScan& out) const {
  for (const VoxelUpdate& v : out.voxels) (v.occupied() ? out.occupied_voxels : out.free_voxels)++;
}

void MapEngine::apply(ShotScan& scan, octomap::OcTree& tree) const {
  const auto t0 = SteadyClock::now();
  octree_stage_.apply(tree, scan.voxels);
  scan.shoot.times.octree_ms += ms_since(t0);
}

}  // namespace ort
