#include "engine/map_engine.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "core/clock.h"
#include "core/map_frame.h"
#include "core/ray_tiles.h"
#include "octree/worker_pool.h"

namespace ort {

namespace {

bool on_device(BackendKind k) { return k == BackendKind::kVulkan || k == BackendKind::kRt; }

// The engine's options with the back end's shared fields filled in from the engine's, and
// whether the cpu-grid walk's helper threads yield (both stages then share the cores).
EngineOptions with_backend_filled(EngineOptions o) {
  o.backend.resolution = o.resolution;
  o.backend.max_range = o.max_range;
  o.backend.traversal = o.traversal;
  o.backend.helpers_yield = o.shoots_beside_apply && o.stage1_helpers_yield && o.backend.threads == 0 &&
                            o.octree.threads == 0;  // read by cpu-grid only
  return o;
}

// The octree stage's threads when the caller left them at 0 and shoots beside apply():
// half the hardware threads beside a cpu-grid walk whose helpers yield (the walk keeps a
// core), all but spare_threads (at least one, at most half) beside a device back end on a
// machine of kSpareCoreAbove threads or more (the stage-1 thread keeps one, the daemon's LCM
// thread more); else as given. Recorded in `o` and returned.
OctreeUpdateOptions settle_octree_threads(EngineOptions& o, BackendKind kind) {
  const unsigned hardware = resolve_thread_count(0);
  if (o.backend.helpers_yield && kind == BackendKind::kCpuGrid) {
    o.octree.threads = std::max(1u, hardware / 2);
  } else if (o.shoots_beside_apply && o.octree.threads == 0 && on_device(kind) && hardware >= kSpareCoreAbove) {
    o.octree.threads = hardware - std::clamp(o.spare_threads, 1u, hardware / 2);
  }
  return o.octree;
}

}  // namespace

// Members in declaration order: the options, the back end they choose, then the octree stage
// whose threads depend on the back end's kind (its threads start on first use).
MapEngine::MapEngine(const EngineOptions& opts, const Log& log)
    : opts_(with_backend_filled(opts)),
      backend_(make_backend(opts_.backend, log)),
      octree_stage_(settle_octree_threads(opts_, backend_->kind())) {}

unsigned MapEngine::octree_threads() const { return resolve_thread_count(opts_.octree.threads); }

std::unique_ptr<octomap::OcTree> MapEngine::make_tree() const {
  auto tree = std::make_unique<octomap::OcTree>(opts_.resolution);
  apply_sensor_model(*tree, opts_.sensor);
  return tree;
}

namespace {

KeyBox widened(const KeyBox& b, int margin) {
  KeyBox w = b;
  for (int i = 0; i < 3; ++i) {
    w.lo[i] = std::max(0, w.lo[i] - margin);
    w.hi[i] = std::min(65535, w.hi[i] + margin);
  }
  return w;
}

bool inside(const KeyBox& b, const VoxelUpdate& v) {
  return v.x >= b.lo[0] && v.x <= b.hi[0] && v.y >= b.lo[1] && v.y <= b.hi[1] && v.z >= b.lo[2] && v.z <= b.hi[2];
}

// A max range the engine can honour on every back end: none (< 0) or at least kMinMaxRange
// (below it, whether a ray is cut depends on squares a GPU may flush to 0).
void check_max_range(double max_range) {
  if (!(max_range < 0.0 || max_range >= kMinMaxRange))
    throw std::invalid_argument("max range " + std::to_string(max_range) + ": below 0 (no limit) or at least " +
                                std::to_string(kMinMaxRange) + " m");
}

void refuse(ShotScan& out, ShotRefusal why, std::string detail) {
  out.refusal = why;
  out.refusal_detail = std::move(detail);
}

}  // namespace

void MapEngine::shoot(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range,
                      ShotScan& out) {
  check_max_range(max_range);
  out.reset();
  const auto t0 = SteadyClock::now();
  RayBatch batch = prepare_scan(origin, points, max_range, opts_.resolution, out.prepare, opts_.octree.threads);
  if (out.prepare.origin_ok && clip_) clip_rays(batch, out);
  out.shoot.times.prepare_ms = ms_since(t0);
  if (!out.prepare.origin_ok) return;
  // Bounded work whatever the geometry: OctoMap's own limit per ray, then the scan's cost
  // (tiles for a box too large for one window) against the configured bound.
  const auto [single, longest] = batch_walk_keys(batch);
  if (longest > kMaxRayWalkKeys)
    return refuse(out, ShotRefusal::kRayTooLong,
                  "a ray walks " + std::to_string(longest) + " keys; OctoMap's ray walk holds at most " +
                      std::to_string(kMaxRayWalkKeys) + " (points too far from the sensor at this resolution)");
  const bool tiled = backend_->kind() != BackendKind::kCpu && widened(batch.keys, 2).voxel_count() > kTiledAbove;
  out.walk_keys = tiled ? tiled_walk_keys(batch, kTileSide) : single;
  if (opts_.max_scan_walk_keys && out.walk_keys > opts_.max_scan_walk_keys)
    return refuse(out, ShotRefusal::kTooMuchWork,
                  "the scan needs " + std::to_string(out.walk_keys) + " ray-walk steps, above the limit of " +
                      std::to_string(opts_.max_scan_walk_keys));
  if (tiled) {
    shoot_tiled(batch, out);
  } else {
    backend_->shoot(batch, opts_.traversal, out.voxels, out.shoot);
  }
  count_states(out);
}

void MapEngine::shoot_posed_xyz(const octomap::pose6d& pose, const octomap::point3d& origin,
                                std::span<const float> sensor_xyz, double max_range, ShotScan& out) {
  if (sensor_xyz.size() % 3) throw std::invalid_argument("scan points: x y z floats, a multiple of 3");
  check_max_range(max_range);
  if (backend_->prepares_on_device()) {
    out.reset();
    // The device shoots what fits one window plan; a far-flung scan comes back declined and
    // takes the CPU path below (tiles along the rays, the per-scan limits), as shoot() does.
    backend_->shoot_posed({&pose, origin, sensor_xyz, max_range, kTiledAbove, opts_.max_scan_walk_keys},
                          opts_.traversal, out.voxels, out.shoot, out.prepare);
    if (!out.prepare.device_declined) {
      count_states(out);
      return;
    }
  }
  const bool declined = out.prepare.device_declined;
  const auto t0 = SteadyClock::now();
  // Straight from the floats into a buffer kept between scans (no copy into point3d first,
  // no fresh pages a scan).
  const size_t n = sensor_xyz.size() / 3;
  if (map_points_.size() < n) map_points_.resize(n);
  const std::span<octomap::point3d> world(map_points_.data(), n);
  transform_to_map_frame(sensor_xyz, world, pose, opts_.octree.threads);
  const double transform_ms = ms_since(t0);
  shoot(origin, world, max_range, out);
  out.prepare.read_as_zero += tiny_as_sent_only(sensor_xyz, world);
  out.shoot.times.prepare_ms += transform_ms;
  out.prepare.device_declined = declined;  // said, so callers can count scans the device passed on
}

// The walk of a ray (OctoMap's DDA) stays inside the key box of its origin and end widened by
// the overstep margin that core/ray_tiles.h plans its tiles with.
void MapEngine::clip_rays(RayBatch& batch, ShotScan& out) const {
  constexpr int kMargin = 2, kKeyMax = 65535;
  KeyBox keys;
  keys.include(batch.origin_key);
  size_t kept = 0;
  for (const RayEnd& e : batch.ends) {
    octomap::OcTreeKey k;
    coord_to_key_checked(octomap::point3d(e.x, e.y, e.z), batch.resolution, k);  // ends are in range
    KeyBox walk;
    for (int i = 0; i < 3; ++i) {
      walk.lo[i] = std::max(0, std::min<int>(batch.origin_key[i], k[i]) - kMargin);
      walk.hi[i] = std::min(kKeyMax, std::max<int>(batch.origin_key[i], k[i]) + kMargin);
    }
    if (!clip_(walk)) continue;
    batch.ends[kept++] = e;
    keys.include(k);
  }
  out.clipped_rays = batch.ends.size() - kept;
  batch.ends.resize(kept);
  batch.keys = keys;
}

// A sum, not an increment of one of two counters chosen per voxel (that chains every voxel
// through a store and a load of the same counter: twice the time on a 300K-voxel list).
void MapEngine::count_states(ShotScan& out) const {
  uint64_t occupied = 0;
  for (const VoxelUpdate& v : out.voxels) occupied += v.occupied() ? 1 : 0;
  out.occupied_voxels += occupied;
  out.free_voxels += out.voxels.size() - occupied;
}

void MapEngine::shoot_tiled(const RayBatch& batch, ShotScan& out) {
  const TilePlan plan = plan_ray_tiles(batch, kTileSide);
  out.tiles = plan.tiles.size();
  RayBatch sub;
  sub.origin = batch.origin;
  sub.origin_key = batch.origin_key;
  sub.resolution = batch.resolution;
  VoxelList part;
  for (const RayTile& tile : plan.tiles) {
    sub.ends.clear();
    for (uint32_t r : tile.rays) sub.ends.push_back(batch.ends[r]);
    sub.keys = tile.box;  // the back end widens it by its margin; what falls outside is the neighbours'
    ShootStats stats;
    backend_->shoot(sub, opts_.traversal, part, stats);
    for (const VoxelUpdate& v : part)
      if (inside(tile.box, v)) out.voxels.push_back(v);
    out.shoot.times.add(stats.times);
    out.shoot.windows += stats.windows;
    out.shoot.words_touched += stats.words_touched;
    out.shoot.words_read_back += stats.words_read_back;
    out.shoot.grid_words = stats.grid_words;
    out.shoot.grid_allocations = stats.grid_allocations;
    out.shoot.walk_overruns += stats.walk_overruns;
  }
}

std::optional<int64_t> MapEngine::apply(ShotScan& scan, octomap::OcTree& tree, LeafChanges* changes) const {
  const auto t0 = SteadyClock::now();
  const std::optional<int64_t> leaf_change = octree_stage_.apply(tree, scan.voxels, changes);
  scan.shoot.times.octree_ms += ms_since(t0);
  return leaf_change;
}

}  // namespace ort
