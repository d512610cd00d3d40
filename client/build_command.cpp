// `octomap-rt build INPUT -r RES -o OUT.bt|OUT.ot`: builds a map from a ScanGraph file or
// the built-in synthetic scene, with progress, stage times and leaf counts.
#include <chrono>
#include <cstdio>
#include <iostream>

#include "commands.h"
#include "core/clock.h"
#include "engine/engine_flags.h"
#include "map_summary.h"
#include "scene/scan_set.h"
#include "scene/synthetic_scene.h"

namespace ort::cli {
namespace {

struct BuildArgs {
  std::string input;
  std::string output;
  EngineFlags engine;
  bool quiet = false;
};

void write_map(const octomap::OcTree& tree, const std::string& path) {
  bool ok = false;
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".bt") == 0) {
    std::ofstream out(path, std::ios::binary);
    ok = out && tree.writeBinaryConst(out) && out.good();
  } else if (path.size() > 3 && path.compare(path.size() - 3, 3, ".ot") == 0) {
    ok = tree.write(path);
  } else {
    throw std::runtime_error("output must end in .bt (OctoMap binary) or .ot (full, with log-odds): " + path);
  }
  if (!ok) throw std::runtime_error("could not write map to " + path);
}

int run_build(const BuildArgs& a) {
  const EngineOptions opts = to_engine_options(a.engine);
  const auto t_load = std::chrono::steady_clock::now();
  const ScanSet set = a.input == "synthetic" ? make_synthetic_rooms() : load_scan_graph(a.input);
  const double load_ms =
      ms_since(t_load);

  MapEngine engine(opts, log_to(std::cerr));
  std::cerr << "octomap-rt build: " << set.scans.size() << " scans, " << set.total_points() << " points from "
            << set.name << " (" << load_ms << " ms)\n"
            << "  back end " << to_string(engine.backend().kind()) << " on " << engine.backend().device_name()
            << ", traversal " << to_string(opts.traversal) << ", resolution " << opts.resolution
            << " m, max range " << opts.max_range << "\n";

  auto tree = engine.make_tree();
  StageTimes total;
  PrepareReport prep_total;
  uint64_t voxels = 0, windows = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < set.scans.size(); ++i) {
    const PosedScan& scan = set.scans[i];
    std::span<const octomap::point3d> pts(scan.points.size() ? &scan.points[0] : nullptr, scan.points.size());
    ShotScan shot;  // sensor-frame points: transformed on the GPU where the back end prepares there
    engine.insert_posed(scan.pose, sensor_origin(scan), pts, *tree, shot);
    if (!shot.prepare.origin_ok) {
      std::cerr << "  scan " << i << " rejected: " << shot.prepare.error << "\n";
      continue;
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
      std::fprintf(stderr, "  [%zu/%zu] %zu points, %zu voxels (%llu occupied), %.1f ms\n", i + 1, set.scans.size(),
                   scan.points.size(), shot.voxels.size(), (unsigned long long)shot.occupied_voxels,
                   shot.shoot.times.total_ms());
    }
  }
  const double wall_ms =
      ms_since(t0);
  write_map(*tree, a.output);

  const MapSummary s = summarize(*tree);
  std::printf("octomap-rt build summary\n");
  std::printf("  scans:           %zu, points %llu, rays %llu\n", set.scans.size(),
              (unsigned long long)prep_total.points_in, (unsigned long long)prep_total.rays);
  std::printf("  skipped points:  %llu non-finite, %llu outside the key range; %llu rays cut at max range\n",
              (unsigned long long)prep_total.nonfinite, (unsigned long long)prep_total.out_of_range,
              (unsigned long long)prep_total.cut_at_max_range);
  if (prep_total.out_of_range)
    std::fprintf(stderr, "octomap-rt build: warning: %llu points lie outside the map's key range (+-%.1f m) and were skipped\n",
                 (unsigned long long)prep_total.out_of_range, 32768 * opts.resolution);
  std::printf("  stage times:     prepare %.1f ms, upload %.1f ms, shoot %.1f ms, compact+readback %.1f ms, octree %.1f ms\n",
              total.prepare_ms, total.upload_ms, total.shoot_ms, total.compact_ms, total.octree_ms);
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
  add_engine_flags(*cmd, args->engine, /*require_resolution=*/true);
  cmd->callback([args] {
    const int rc = run_build(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace ort::cli
