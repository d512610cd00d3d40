// `octomap-rt build INPUT -r RES -o OUT.bt|OUT.ot`: builds a map from a ScanGraph file or
// the built-in synthetic scene, with progress, stage times and leaf counts.
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>

#include "cli/commands.h"
#include "cli/map_summary.h"
#include "core/clock.h"
#include "core/file_checks/octree_binary.h"
#include "core/log.h"
#include "engine/engine_flags.h"
#include "engine/engine_pipeline.h"
#include "scene/scan_set.h"
#include "scene/synthetic_scene.h"

namespace ort::cli {
namespace {

struct BuildArgs {
  std::string input;
  std::string output;
  EngineFlags engine;
  bool quiet = false;
  bool no_pipeline = false;
};

// Writes the map and checks the stream only after closing it: a full disk shows when the
// buffered bytes are flushed, not when OctoMap's writer returns. A failed write removes the
// partial file and is an error (the command exits non-zero).
void write_map(const octomap::OcTree& tree, const std::string& path) {
  const bool bt = path.size() > 3 && path.compare(path.size() - 3, 3, ".bt") == 0;
  const bool ot = path.size() > 3 && path.compare(path.size() - 3, 3, ".ot") == 0;
  if (!bt && !ot)
    throw std::runtime_error("output must end in .bt (OctoMap binary) or .ot (full, with log-odds): " + path);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot create " + path + ": " + std::strerror(errno));
  const bool written = bt ? write_octomap_binary(tree, out) : tree.write(out);
  errno = 0;
  out.close();
  if (!written || out.fail()) {
    const std::string why = errno ? std::strerror(errno) : "write failed";
    std::remove(path.c_str());
    throw std::runtime_error("could not write the map to " + path + ": " + why + " (disk full?); nothing was written");
  }
}

int run_build(const BuildArgs& a) {
  EngineOptions opts = to_engine_options(a.engine);
  opts.shoots_beside_apply = !a.no_pipeline;
  opts.stage1_helpers_yield = true;
  const auto t_load = SteadyClock::now();
  const ScanSet set = a.input == "synthetic" ? make_synthetic_rooms() : load_scan_graph(a.input);
  const double load_ms = ms_since(t_load);

  const Log log = log_to(std::cerr, "octomap-rt build");
  MapEngine engine(opts, log);
  log.info(text(set.scans.size(), " scans, ", set.total_points(), " points from ", set.name, " (", load_ms, " ms)"));
  log.info(text("back end ", to_string(engine.backend().kind()), " on ", engine.backend().device_name(), ", traversal ",
                to_string(opts.traversal), ", resolution ", opts.resolution, " m, max range ", opts.max_range,
                ", octree threads ", engine.octree_threads()));

  auto tree = engine.make_tree();
  StageTimes total;
  PrepareReport prep_total;
  uint64_t voxels = 0, windows = 0;
  size_t rejected = 0;
  const auto t0 = SteadyClock::now();
  const auto scan_input = [&set](size_t i) {  // sensor-frame points: transformed on the GPU where it prepares
    const PosedScan& scan = set.scans[i];
    std::span<const octomap::point3d> pts(scan.points.size() ? &scan.points[0] : nullptr, scan.points.size());
    return PosedScanInput{scan.pose, sensor_origin(scan), pts};
  };
  // Called in scan order once the scan is in the map (on the octree stage's thread when pipelined).
  const auto account = [&](size_t i, const ShotScan& shot) {
    if (!shot.prepare.origin_ok || shot.refusal != ShotRefusal::kNone) {
      ++rejected;
      std::cerr << "  scan " << i
                << " rejected: " << (shot.prepare.origin_ok ? shot.refusal_detail : shot.prepare.error) << "\n";
      return;
    }
    total.add(shot.shoot.times);
    prep_total.points_in += shot.prepare.points_in;
    prep_total.rays += shot.prepare.rays;
    prep_total.nonfinite += shot.prepare.nonfinite;
    prep_total.out_of_range += shot.prepare.out_of_range;
    prep_total.cut_at_max_range += shot.prepare.cut_at_max_range;
    voxels += shot.voxels.size();
    windows += shot.shoot.windows;
    if (!a.quiet) {
      const StageTimes& t = shot.shoot.times;
      std::fprintf(stderr,
                   "  [%zu/%zu] %zu points, %zu voxels (%llu occupied), %.1f ms (stage 1 %.1f, of which "
                   "compact+readback %.1f; octree %.1f)\n",
                   i + 1, set.scans.size(), set.scans[i].points.size(), shot.voxels.size(),
                   (unsigned long long)shot.occupied_voxels, t.total_ms(), t.total_ms() - t.octree_ms, t.compact_ms,
                   t.octree_ms);
    }
  };
  insert_scans(engine, set.scans.size(), scan_input, *tree, account, !a.no_pipeline);
  const double wall_ms = ms_since(t0);
  write_map(*tree, a.output);

  const MapSummary s = summarize(*tree);
  std::printf("octomap-rt build summary\n");
  std::printf("  scans:           %zu, points %llu, rays %llu\n", set.scans.size(),
              (unsigned long long)prep_total.points_in, (unsigned long long)prep_total.rays);
  std::printf("  skipped points:  %llu non-finite, %llu outside the key range; %llu rays cut at max range\n",
              (unsigned long long)prep_total.nonfinite, (unsigned long long)prep_total.out_of_range,
              (unsigned long long)prep_total.cut_at_max_range);
  if (rejected > 0 && rejected == set.scans.size())
    std::fprintf(stderr,
                 "octomap-rt build: warning: every scan was rejected (see above; the key range is +-%g m at -r %g): "
                 "the map is empty; is the resolution right?\n",
                 32768 * opts.resolution, opts.resolution);
  else if (prep_total.out_of_range && prep_total.out_of_range == prep_total.points_in - prep_total.nonfinite)
    std::fprintf(stderr,
                 "octomap-rt build: warning: every point lies outside the map's key range (+-%g m at -r %g): the map "
                 "is empty; is the resolution right?\n",
                 32768 * opts.resolution, opts.resolution);
  else if (prep_total.out_of_range)
    std::fprintf(stderr,
                 "octomap-rt build: warning: %llu points lie outside the map's key range (+-%.1f m) and were skipped\n",
                 (unsigned long long)prep_total.out_of_range, 32768 * opts.resolution);
  std::printf(
      "  stage times:     prepare %.1f ms, upload %.1f ms, shoot %.1f ms, compact+readback %.1f ms, octree %.1f ms\n",
      total.prepare_ms, total.upload_ms, total.shoot_ms, total.compact_ms, total.octree_ms);
  if (total.compact_gpu_ms + total.readback_copy_ms + total.unpack_ms > 0)
    std::printf(
        "  compact+readback: GPU compaction %.1f ms, copy to host memory %.1f ms, into the voxel list %.1f ms\n",
        total.compact_gpu_ms, total.readback_copy_ms, total.unpack_ms);
  std::printf("  total:           %.1f ms, %.0f points/s, %llu voxel updates, %llu windows\n", wall_ms,
              wall_ms > 0 ? prep_total.points_in / (wall_ms / 1000.0) : 0.0, (unsigned long long)voxels,
              (unsigned long long)windows);
  std::ostringstream os;
  print_summary(os, s);
  std::printf("%s", os.str().c_str());
  std::printf("  map written to:  %s\n", a.output.c_str());
  return 0;
}

}  // namespace

void register_build_command(CLI::App& app) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* cmd = app.add_subcommand("build", "build a map from a ScanGraph (.graph) file or the built-in scene");
  cmd->add_option("INPUT", args->input, "OctoMap ScanGraph .graph file, or 'synthetic' for the built-in scene")
      ->required();
  cmd->add_option("-o,--output", args->output, "map file: .bt (OctoMap binary) or .ot (with log-odds)")->required();
  cmd->add_flag("-q,--quiet", args->quiet, "no per-scan progress lines");
  cmd->add_flag("--no-pipeline", args->no_pipeline,
                "run the two stages one scan after the other (default: scan k+1 is shot while scan k's octree "
                "update runs); the stage times are each stage's sum, the total is the wall clock either way");
  add_engine_flags(*cmd, args->engine, /*require_resolution=*/true);
  cmd->callback([args] {
    const int rc = run_build(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace ort::cli
