// The engine's one interface: insert a scan into a map.
//
// It is split into the two pipeline stages the server runs on two threads:
//   shoot()  — stage 1 (GPU): prepare rays, shoot them, read back the voxel list;
//   apply()  — stage 2 (CPU): update the octree with that list.
// insert() runs both in sequence. shoot() and apply() may run concurrently on different
// scans; neither may be called from two threads at once.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <octomap/OcTree.h>

#include "core/log.h"
#include "core/prepare_scan.h"
#include "core/ray_backend.h"
#include "core/sensor_model.h"
#include "engine/backend_factory.h"
#include "octree/octree_update.h"

namespace ort {

struct EngineOptions {
  double resolution = 0.1;
  double max_range = -1.0;  // < 0: no limit (OctoMap's default)
  Traversal traversal = Traversal::kOctomap;
  BackendOptions backend;  // resolution/max_range are filled in from above
  OctreeUpdateOptions octree;
  SensorModel sensor;
  // Most key steps one scan may cost (the sum over its windows of the walks of their rays);
  // a scan above it is refused before any ray is shot. 0: no limit. The default is 2.5x a
  // 4M-point scan of 1000-voxel rays; far-flung but small scans stay far below it.
  uint64_t max_scan_walk_keys = 10'000'000'000ull;
  // Set by callers that shoot the next scan on another thread while apply() runs
  // (engine/engine_pipeline.h). With a device back end (vulkan, rt), octree.threads = 0 and
  // at least kSpareCoreAbove hardware threads, the octree stage then keeps one hardware
  // thread free for that stage-1 thread: with a worker on every core, stage 1 preempts one
  // and the others wait for it at each of the stage's joins (docs/history/benchmarks-log.md).
  bool shoots_beside_apply = false;
  // The hardware threads the octree stage then leaves to others (at most half of them): 1,
  // stage 1's, in bench and build. The daemon leaves more (its LCM thread receives and
  // decodes ~1 GB/s of scans beside the kernel's network work: server_cli.cpp).
  unsigned spare_threads = 1;
  // Set by the batch programs (bench, build) beside shoots_beside_apply. With the cpu-grid
  // back end and both thread counts at 0, the octree stage takes half the hardware threads
  // (at least one) and the walk all of them, its helper threads at the lowest priority: the
  // walk then has a core of its own and the octree stage's idle ones: on 2 cores the sets that
  // stage 1 dominates ran faster than with one thread a stage (docs/history/benchmarks-log.md,
  // "the cpu-grid walk").
  // Not for the daemon: a helper starved by other processes would hold up a scan.
  bool stage1_helpers_yield = false;
};

// Fewer hardware threads than this: every one goes to the octree stage (on a few cores one
// worker less costs the stage more than the preemption does).
inline constexpr unsigned kSpareCoreAbove = 8;

// Why shoot() refused a scan whose origin was fine (the scan is then not shot at all).
enum class ShotRefusal {
  kNone,
  kRayTooLong,   // a ray's walk exceeds OctoMap's KeyRay (100,000 keys): OctoMap cannot insert it
  kTooMuchWork,  // the scan's walk keys exceed EngineOptions::max_scan_walk_keys
};

// One scan on its way through the pipeline.
struct ShotScan {
  PrepareReport prepare;
  ShootStats shoot;
  VoxelList voxels;
  uint64_t free_voxels = 0, occupied_voxels = 0;
  uint64_t walk_keys = 0;     // the scan's cost: key steps over all its windows
  uint64_t tiles = 0;         // path-following tiles (0: the scan's box was shot whole)
  uint64_t clipped_rays = 0;  // rays left out by the engine's ray clip (a shard's: set_ray_clip)
  ShotRefusal refusal = ShotRefusal::kNone;
  std::string refusal_detail;  // says why, with the numbers

  // Ready for the next scan, as a fresh ShotScan but keeping the voxel list's storage: a
  // large scan's list (campus: 60 MB) allocated anew each scan costs a page fault every 4 KiB
  // (the allocator returns such blocks to the system when they are freed).
  void reset() {
    VoxelList keep = std::move(voxels);
    keep.clear();
    *this = ShotScan{};
    voxels = std::move(keep);
  }
};

class MapEngine {
 public:
  // Throws std::runtime_error (or Unsupported) when the requested back end cannot be made.
  // Messages about the device choice (or the fallback to cpu) go to `log`.
  explicit MapEngine(const EngineOptions& opts, const Log& log = {});

  // A fresh map with this engine's resolution and sensor model.
  std::unique_ptr<octomap::OcTree> make_tree() const;

  // Stage 1. `max_range` overrides the engine's when >= -1 is not wanted: pass opts' value.
  // A max range that is neither < 0 (no limit) nor >= kMinMaxRange throws std::invalid_argument.
  void shoot(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range, ShotScan& out);
  // Stage 1 for a scan in the sensor frame: `pose` takes the points into the map frame (as
  // OctoMap's Pointcloud::transform), `origin` is the sensor origin in the map frame. The
  // back end prepares it on its device where it can (BackendOptions::gpu_prepare), else the
  // CPU transforms and prepares; the rays are the same either way, bit for bit.
  // out.shoot.times.prepare_ms includes the transform.
  void shoot_posed(const octomap::pose6d& pose, const octomap::point3d& origin,
                   std::span<const octomap::point3d> sensor_points, double max_range, ShotScan& out) {
    shoot_posed_xyz(pose, origin, as_xyz(sensor_points), max_range, out);
  }
  // The same with the points as x y z floats (a scan message's layout): a back end that
  // prepares on its device copies them straight into its upload buffer.
  void shoot_posed_xyz(const octomap::pose6d& pose, const octomap::point3d& origin, std::span<const float> sensor_xyz,
                       double max_range, ShotScan& out);
  // Stage 2. Adds its time to out.shoot.times.octree_ms. With `changes`: reset, then every
  // finest leaf the update changed, its value before and after (octree/leaf_changes.h).
  // Returns the change of the tree's leaf count, where the octree stage knows it
  // (OctreeStage::apply).
  std::optional<int64_t> apply(ShotScan& scan, octomap::OcTree& tree, LeafChanges* changes = nullptr) const;
  // Both stages.
  void insert(const octomap::point3d& origin, std::span<const octomap::point3d> points, octomap::OcTree& tree,
              ShotScan& out) {
    shoot(origin, points, opts_.max_range, out);
    apply(out, tree);
  }

  // Both stages, for a scan in the sensor frame.
  void insert_posed(const octomap::pose6d& pose, const octomap::point3d& origin,
                    std::span<const octomap::point3d> sensor_points, octomap::OcTree& tree, ShotScan& out) {
    shoot_posed(pose, origin, sensor_points, opts_.max_range, out);
    apply(out, tree);
  }

  // A shard's ray clip (docs/PROTOCOL.md, "Shards"): `may_hold(box)` says whether the inclusive
  // key box may hold a voxel the caller keeps; it must never say false for a box that does. A
  // ray whose walk stays in a box `may_hold` refuses (its origin's and end's keys, widened by
  // the DDA's overstep margin) is left out before the walk; the rays kept are walked whole, as
  // OctoMap walks them, so every voxel kept gets OctoMap's update (a voxel's update depends only
  // on the rays through it). On the CPU preparation path only: a back end that prepares scans
  // on its device walks every ray. An empty function (the default) keeps every ray.
  using RayClip = std::function<bool(const KeyBox&)>;
  void set_ray_clip(RayClip may_hold) { clip_ = std::move(may_hold); }

  const EngineOptions& options() const { return opts_; }
  // The batched octree stage's threads (0 in opts_.octree: all hardware threads).
  unsigned octree_threads() const;
  const RayBackend& backend() const { return *backend_; }

  // A scan whose widened key box holds more voxels than this is shot tile by tile
  // (core/ray_tiles.h) by the back ends with a grid; tiles have kTileSide keys a side, so a
  // tile with its margins fits a 1 GiB-voxel grid window.
  static constexpr uint64_t kTiledAbove = 1ull << 30;
  static constexpr int kTileSide = 1016;

 private:
  void count_states(ShotScan& out) const;
  // Leaves out the rays clip_ refuses; the batch's key box then bounds the rays kept.
  void clip_rays(RayBatch& batch, ShotScan& out) const;
  // Shoots a scan too large for one window tile by tile, each tile's voxels cut to it.
  void shoot_tiled(const RayBatch& batch, ShotScan& out);

  EngineOptions opts_;
  RayClip clip_;
  std::unique_ptr<RayBackend> backend_;
  mutable OctreeStage octree_stage_;          // keeps the batched stage's threads between scans; only apply() uses it
  std::vector<octomap::point3d> map_points_;  // shoot_posed_xyz's map-frame points, kept between scans
};

}  // namespace ort
