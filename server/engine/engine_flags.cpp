#include "engine/engine_flags.h"

#include <cmath>

namespace ort::cli {

void add_engine_flags(CLI::App& cmd, EngineFlags& f, bool require_resolution) {
  auto* r = cmd.add_option("-r,--resolution", f.resolution, "voxel edge length [m]")->check(CLI::PositiveNumber);
  if (require_resolution) r->required();
  cmd.add_option("--max-range", f.max_range, "cut rays longer than this [m]; < 0: no limit")->capture_default_str();
  cmd.add_option("--backend", f.backend,
                 "ray shooting: auto, cpu (OctoMap's own walk, the reference), cpu-grid (native threads "
                 "into the 2-bit grid), vulkan (compute shaders) or rt (ray-tracing pipeline: --traversal exact "
                 "only; needs VK_KHR_ray_tracing_pipeline, else it reports unsupported)")
      ->check(CLI::IsMember(backend_names()))
      ->capture_default_str();
  cmd.add_option("--device", f.device, "Vulkan device: name substring or index (default: automatic)");
  cmd.add_option("--traversal", f.traversal,
                 "octomap (OctoMap's exact walk) or exact (closed-box geometry; the only mode of --backend rt)")
      ->check(CLI::IsMember({"octomap", "exact"}))
      ->capture_default_str();
  cmd.add_option("--octree", f.octree, "octree stage: sequential (updateNode loop) or batched")
      ->check(CLI::IsMember({"sequential", "batched"}))
      ->capture_default_str();
  cmd.add_option("--threads", f.threads, "threads of the CPU stages (octree, cpu-grid rays); 0: all hardware threads")
      ->capture_default_str();
  cmd.add_option("--prob-hit", f.sensor.prob_hit, "sensor model: P(occupied | hit)")->capture_default_str();
  cmd.add_option("--prob-miss", f.sensor.prob_miss, "sensor model: P(occupied | miss)")->capture_default_str();
  cmd.add_option("--clamp-min", f.sensor.clamping_min, "sensor model: lower clamping probability")
      ->capture_default_str();
  cmd.add_option("--clamp-max", f.sensor.clamping_max, "sensor model: upper clamping probability")
      ->capture_default_str();
  cmd.add_option("--occupancy-threshold", f.sensor.occupancy_threshold, "sensor model: occupied above this")
      ->capture_default_str();
}

EngineOptions to_engine_options(const EngineFlags& f) {
  EngineOptions o;
  // OctoMap's keys have 16 bits a side, so the map spans 65536 voxels: outside this range a
  // resolution gives a map of micrometres or of continents, and NaN gives no map at all.
  if (!(f.resolution >= kMinResolution && f.resolution <= kMaxResolution))
    throw CLI::ValidationError("--resolution", "must lie within [0.0001, 1000] m, not " + std::to_string(f.resolution));
  if (!std::isfinite(f.max_range))
    throw CLI::ValidationError("--max-range", "must be a finite number of metres (< 0: no limit)");
  if (f.max_range >= 0 && f.max_range < kMinMaxRange)
    throw CLI::ValidationError("--max-range", "must be at least " + std::to_string(kMinMaxRange) +
                                                  " m (or < 0: no limit), not " + std::to_string(f.max_range));
  o.resolution = f.resolution;
  o.max_range = f.max_range;
  if (!parse_backend(f.backend, o.backend.kind))
    throw CLI::ValidationError("--backend", "unknown back end " + f.backend);
  if (!parse_traversal(f.traversal, o.traversal))
    throw CLI::ValidationError("--traversal", "unknown traversal " + f.traversal);
  o.backend.device = f.device;
  o.backend.threads = f.threads;
  o.octree.mode = f.octree == "batched" ? OctreeUpdateMode::kBatched : OctreeUpdateMode::kSequential;
  o.octree.threads = f.threads;
  auto prob = [](double p, const char* name) {
    if (!(p > 0.0 && p < 1.0)) throw CLI::ValidationError(name, "must lie strictly between 0 and 1");
  };
  prob(f.sensor.prob_hit, "--prob-hit");
  prob(f.sensor.prob_miss, "--prob-miss");
  prob(f.sensor.clamping_min, "--clamp-min");
  prob(f.sensor.clamping_max, "--clamp-max");
  prob(f.sensor.occupancy_threshold, "--occupancy-threshold");
  if (f.sensor.clamping_min >= f.sensor.clamping_max)
    throw CLI::ValidationError("--clamp-min", "must be below --clamp-max");
  o.sensor = f.sensor;
  return o;
}

}  // namespace ort::cli
