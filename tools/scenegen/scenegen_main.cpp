// octomap-rt-scenegen: makes a preset scene's scans (see scene/scene_presets.h) and writes
// them as an OctoMap ScanGraph, readable by `octomap-rt build`, `bench` and OctoMap's own
// graph2tree.
#include <chrono>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "core/clock.h"
#include "scene/scan_set.h"
#include "scene/scene_presets.h"

using ort::seconds_since;
using ort::SteadyClock;

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-scenegen: deterministic procedural scan sets at the scale of the OctoMap-RT paper"};
  std::string preset, output, scale = "1", scan_scale, point_scale;
  ort::PresetOptions opts;
  bool list = false;
  app.add_option("PRESET", preset, "fr079, campus, skt-corridor or fr079-real");
  app.add_option("-o,--output", output, "ScanGraph file to write (.graph)");
  app.add_option("--scale", scale, "tiny, ci or a share in (0, 1] of both scans and points")->capture_default_str();
  app.add_option("--scan-scale", scan_scale, "share of the scans (overrides --scale for scans)");
  app.add_option("--point-scale", point_scale, "share of the points per scan (overrides --scale for points)");
  app.add_option("--seed", opts.seed, "scene and noise seed")->capture_default_str();
  app.add_option("--robots", opts.robots, "robots sharing the tour (0: the preset's own)")->capture_default_str();
  app.add_option("--threads", opts.threads, "generation threads (0: all)")->capture_default_str();
  app.add_option("--data", opts.data_dir, "data folder holding octomap_share/geb079.bt (for fr079-real)");
  app.add_flag("--list", list, "list the presets and exit");
  CLI11_PARSE(app, argc, argv);
  if (list) {
    for (const auto& p : ort::preset_catalog())
      std::printf("%-13s %3d scans of ~%.0fK points  %s\n", p.name.c_str(), p.scans, p.points_per_scan / 1e3,
                  p.description.c_str());
    return 0;
  }
  try {
    if (preset.empty() || output.empty()) throw std::runtime_error("PRESET and -o are required (or --list)");
    opts.scan_scale = opts.point_scale = ort::parse_scale(scale);
    if (!scan_scale.empty()) opts.scan_scale = ort::parse_scale(scan_scale);
    if (!point_scale.empty()) opts.point_scale = ort::parse_scale(point_scale);
    const auto t0 = SteadyClock::now();
    const ort::ScanSet set = ort::make_preset(preset, opts);
    const double gen_s = seconds_since(t0);
    ort::save_scan_graph(set, output);
    std::printf("%s: %zu scans, %zu points (%.0f a scan), generated in %.2f s, written to %s\n", preset.c_str(),
                set.scans.size(), set.total_points(), double(set.total_points()) / set.scans.size(), gen_s,
                output.c_str());
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-scenegen: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
