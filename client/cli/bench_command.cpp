// `octomap-rt bench`: data sets x resolutions x mappers, against OctoMap's insertPointCloud
// in the same process on the same scans. Per run: stage breakdown (paper Fig. 6), end-to-end
// ratio, leaf counts against OctoMap's (Fig. 10), tree and process memory, the GPU grid.
// Writes CSV, Markdown tables and gnuplot charts; progress goes to stderr.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "cli/bench/bench_plot.h"
#include "cli/bench/bench_results.h"
#include "cli/bench/octomap_reference.h"
#include "cli/bench/process_memory.h"
#include "cli/commands.h"
#include "cli/map_summary.h"
#include "core/clock.h"
#include "core/log.h"
#include "engine/engine_pipeline.h"
#include "engine/map_engine.h"
#include "scene/scan_set.h"
#include "scene/scene_presets.h"

namespace ort::cli {
namespace {

using bench::BenchRow;

struct BenchArgs {
  std::vector<std::string> presets = {"fr079", "campus", "skt-corridor"};
  std::vector<std::string> graphs;
  std::string data_dir;
  std::string scale = "1", scan_scale, point_scale;
  uint64_t seed = 1;
  std::vector<double> resolutions = {0.1, 0.2, 0.4, 0.8};
  std::vector<std::string> backends = {"cpu", "cpu-grid", "vulkan", "rt"};
  std::vector<std::string> traversals = {"octomap", "exact"};
  std::vector<std::string> octrees = {"sequential"};
  unsigned threads = 0;
  double max_range = -1.0;
  std::string device;
  int warmup = 1, repeat = 1;
  bool no_octomap_breakdown = false;
  bool no_pipeline = false;
  std::vector<std::string> prepares = {"device"};
  std::string csv, png_dir, markdown;
  std::vector<std::string> replot;
};

double diff_pct(uint64_t ours, uint64_t theirs) {
  return theirs ? 100.0 * (double(ours) - double(theirs)) / double(theirs) : 0.0;
}

std::span<const octomap::point3d> as_span(const octomap::Pointcloud& pc) {
  return {pc.size() ? &pc[0] : nullptr, pc.size()};
}

// (back end, preparation) pairs to measure: only vulkan prepares on its device, so other
// back ends get one row whatever --prepare lists.
std::vector<std::pair<std::string, std::string>> backend_configs(const BenchArgs& a) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& backend : a.backends) {
    for (const auto& prepare : a.prepares) {
      if (backend == "vulkan" || prepare == a.prepares.front()) out.emplace_back(backend, prepare);
    }
  }
  return out;
}

void run_engine(const ScanSet& set, const EngineOptions& opts, const BenchArgs& a, const bench::OctomapReference& ref,
                BenchRow& r) {
  MapEngine engine(opts);  // the device is in the row; the creation notes are not wanted here
  r.device = engine.backend().device_name();
  const size_t warm = std::min<size_t>(a.warmup, set.scans.size());
  // Sensor-frame points: the engine transforms (on the CPU or the GPU).
  const ScanInputSource scan_input = [&set](size_t i) {
    const PosedScan& s = set.scans[i];
    return PosedScanInput{s.pose, sensor_origin(s), as_span(s.points)};
  };
  {  // warm-up: pipelines, first allocations, page faults of the grid
    auto scratch = engine.make_tree();
    insert_scans(engine, warm, scan_input, *scratch, {}, !a.no_pipeline);
  }
  std::vector<std::pair<double, BenchRow>> runs;
  std::unique_ptr<octomap::OcTree> tree;
  for (int rep = 0; rep < a.repeat; ++rep) {
    BenchRow m = r;
    tree = engine.make_tree();
    StageTimes st;
    const auto t0 = SteadyClock::now();
    // Stage times are each stage's own sum; with the pipeline they overlap in the total.
    insert_scans(
        engine, set.scans.size(), scan_input, *tree,
        [&](size_t, const ShotScan& shot) {
          st.add(shot.shoot.times);
          m.windows += shot.shoot.windows;
          m.voxel_updates += shot.voxels.size();
          m.gpu_grid_bytes = std::max<uint64_t>(m.gpu_grid_bytes, shot.shoot.grid_words * 4);
        },
        !a.no_pipeline);
    m.total_ms = ms_since(t0);
    m.prepare_ms = st.prepare_ms;  // transform included
    m.upload_ms = st.upload_ms;
    m.shoot_ms = st.shoot_ms;
    m.compact_ms = st.compact_ms;
    m.octree_ms = st.octree_ms;
    runs.push_back({m.total_ms, m});
  }
  std::sort(runs.begin(), runs.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  r = runs[runs.size() / 2].second;  // the median run, with its own stage times
  const MapSummary s = summarize(*tree);
  r.free_voxels = s.finest_free;
  r.occupied_voxels = s.finest_occupied;
  r.free_diff_pct = diff_pct(s.finest_free, ref.summary.finest_free);
  r.occupied_diff_pct = diff_pct(s.finest_occupied, ref.summary.finest_occupied);
  r.counts_equal =
      (s.finest_free == ref.summary.finest_free && s.finest_occupied == ref.summary.finest_occupied) ? "yes" : "no";
  r.map_identical = bench::same_leaves(*tree, *ref.tree) ? "yes" : "no";
  r.tree_bytes = tree->memoryUsage();
  r.rss_bytes = current_rss_bytes();
  r.peak_rss_bytes = peak_rss_bytes();
  r.octomap_total_ms = ref.row.total_ms;
  r.speedup = r.total_ms > 0 ? ref.row.total_ms / r.total_ms : 0.0;
  r.points_per_s = r.total_ms > 0 ? r.points / (r.total_ms / 1000.0) : 0.0;
}

std::vector<std::pair<std::string, std::string>> datasets(const BenchArgs& a) {
  // (name, source): source "preset" or a .graph path
  std::vector<std::pair<std::string, std::string>> d;
  for (const auto& p : a.presets)
    if (p != "none") d.push_back({p, "preset"});
  for (const auto& g : a.graphs) d.push_back({g, g});
  if (!a.data_dir.empty()) {
    for (const char* rel : {"3dtk_dat/3dtk_3scans.graph", "octomap_share/scan_dat.graph"}) {
      const std::string path = a.data_dir + "/" + rel;
      if (std::filesystem::exists(path))
        d.push_back({std::filesystem::path(rel).filename().string(), path});
      else
        log_to(std::cerr, "octomap-rt bench").warning(path + " not found, skipped");
    }
    const bool listed = std::find(a.presets.begin(), a.presets.end(), "fr079-real") != a.presets.end();
    if (!listed && std::filesystem::exists(a.data_dir + "/octomap_share/geb079.bt"))
      d.push_back({"fr079-real", "preset"});
  }
  return d;
}

void save_outputs(const std::vector<BenchRow>& rows, const BenchArgs& a) {
  if (!a.csv.empty()) {
    std::ofstream out(a.csv);
    bench::write_csv(rows, out);
    if (!out) throw std::runtime_error("cannot write " + a.csv);
  }
  if (!a.markdown.empty()) {
    std::ofstream out(a.markdown);
    bench::write_markdown(rows, out);
    if (!out) throw std::runtime_error("cannot write " + a.markdown);
  }
  if (!a.png_dir.empty()) {
    std::string msg;
    if (!bench::plot_stage_charts(rows, a.png_dir, msg))
      log_to(std::cerr, "octomap-rt bench").warning("charts: " + msg);
  }
}

int run_bench(const BenchArgs& a) {
  if (!a.replot.empty()) {  // chart and table a CSV measured elsewhere (the GPU machine)
    std::vector<BenchRow> rows;
    for (const auto& path : a.replot) {
      auto more = bench::read_csv(path);
      rows.insert(rows.end(), more.begin(), more.end());
    }
    save_outputs(rows, a);
    if (a.markdown.empty()) bench::write_markdown(rows, std::cout);
    return 0;
  }
  PresetOptions popts;
  popts.scan_scale = popts.point_scale = parse_scale(a.scale);
  if (!a.scan_scale.empty()) popts.scan_scale = parse_scale(a.scan_scale);
  if (!a.point_scale.empty()) popts.point_scale = parse_scale(a.point_scale);
  popts.seed = a.seed;
  popts.data_dir = a.data_dir;

  std::vector<BenchRow> rows;
  const auto sets = datasets(a);
  if (sets.empty()) throw std::runtime_error("nothing to measure: give --preset, --graph or --data");
  for (const auto& [name, source] : sets) {
    std::unique_ptr<ScanSet> set;
    const auto tg = SteadyClock::now();
    try {
      set = std::make_unique<ScanSet>(source == "preset" ? make_preset(name, popts) : load_scan_graph(source));
    } catch (const std::exception& e) {
      log_to(std::cerr, "octomap-rt bench").warning(text(name, ": ", e.what(), " (skipped)"));
      BenchRow r;
      r.dataset = name;
      r.backend = "octomap";
      r.status = std::string("no data: ") + e.what();
      rows.push_back(r);
      continue;
    }
    char took[32];
    std::snprintf(took, sizeof took, "%.1f", ms_since(tg) / 1000.0);
    log_to(std::cerr, "octomap-rt bench")
        .info(text(name, ": ", set->scans.size(), " scans, ", set->total_points(), " points (", took, " s to ",
                   source == "preset" ? "generate" : "load", ")"));
    for (double res : a.resolutions) {
      BenchRow base;
      base.dataset = name;
      base.scans = set->scans.size();
      base.points = set->total_points();
      base.resolution = res;
      base.max_range = a.max_range;
      base.warmup_scans = std::min<int>(a.warmup, int(set->scans.size()));
      base.repeats = a.repeat;
      std::fprintf(stderr, "  %s @ %.2f m: OctoMap insertPointCloud ...", name.c_str(), res);
      bench::OctomapReference ref =
          bench::run_octomap(*set, base, {a.warmup, a.repeat, a.max_range, !a.no_octomap_breakdown});
      const BenchRow& oct = ref.row;
      rows.push_back(oct);
      std::fprintf(stderr, " %.2f s\n", oct.total_ms / 1000.0);
      for (const auto& [backend, prepare] : backend_configs(a)) {
        for (const auto& traversal : a.traversals) {
          for (const auto& octree : a.octrees) {
            BenchRow r = base;
            r.backend = backend == "vulkan" && prepare == "cpu" ? "vulkan/cpu-prep" : backend;
            r.traversal = traversal;
            r.octree = octree;
            r.octomap_free = ref.summary.finest_free;
            r.octomap_occupied = ref.summary.finest_occupied;
            r.octomap_total_ms = oct.total_ms;
            EngineOptions opts;
            opts.resolution = res;
            opts.max_range = a.max_range;
            if (!parse_backend(backend, opts.backend.kind)) throw std::runtime_error("unknown back end " + backend);
            if (!parse_traversal(traversal, opts.traversal)) throw std::runtime_error("unknown traversal " + traversal);
            opts.backend.device = a.device;
            opts.backend.threads = a.threads;
            opts.backend.gpu_prepare = prepare == "device";
            opts.octree.mode = octree == "batched" ? OctreeUpdateMode::kBatched : OctreeUpdateMode::kSequential;
            opts.octree.threads = a.threads;
            opts.shoots_beside_apply = !a.no_pipeline;
            opts.stage1_helpers_yield = true;
            std::fprintf(stderr, "  %s @ %.2f m: %s, %s traversal, %s octree ...", name.c_str(), res, backend.c_str(),
                         traversal.c_str(), octree.c_str());
            try {
              run_engine(*set, opts, a, ref, r);
              std::fprintf(stderr, " %.2f s, %.1fx, map %s\n", r.total_ms / 1000.0, r.speedup,
                           r.map_identical == "yes" ? "identical to OctoMap's"
                           : traversal == "octomap" ? "DIFFERS from OctoMap's"
                                                    : "differs (expected in exact mode)");
            } catch (const std::exception& e) {
              r.status = std::string("unavailable: ") + e.what();
              std::fprintf(stderr, " %s\n", r.status.c_str());
            }
            rows.push_back(r);
          }
        }
      }
      save_outputs(rows, a);  // after each group: a long run interrupted still leaves its results
    }
  }
  if (a.markdown.empty()) bench::write_markdown(rows, std::cout);
  int mismatches = 0;
  for (const BenchRow& r : rows)
    if (r.status == "ok" && r.backend != "octomap" && r.traversal == "octomap" && r.map_identical != "yes")
      ++mismatches;
  if (mismatches) {
    log_to(std::cerr, "octomap-rt bench")
        .error(text(mismatches, " octomap-mode run(s) did NOT reproduce OctoMap's map"));
    return 3;
  }
  return 0;
}

}  // namespace

void register_bench_command(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "benchmark data sets x resolutions x back ends against OctoMap's insertPointCloud, in one process");
  cmd->add_option("--preset", a->presets, "presets to generate: fr079, campus, skt-corridor, fr079-real; none")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--graph", a->graphs, "ScanGraph files to measure as well")->delimiter(',');
  cmd->add_option("--data", a->data_dir,
                  "data folder (../shared/data): adds 3dtk_3scans.graph, scan_dat.graph and fr079-real when present");
  cmd->add_option("--scale", a->scale, "preset size: tiny, ci or a share in (0, 1] of scans and points")
      ->capture_default_str();
  cmd->add_option("--scan-scale", a->scan_scale, "share of the preset's scans (overrides --scale)");
  cmd->add_option("--point-scale", a->point_scale, "share of the points per scan (overrides --scale)");
  cmd->add_option("--seed", a->seed, "preset seed")->capture_default_str();
  cmd->add_option("-r,--resolutions", a->resolutions, "voxel sizes [m]")->delimiter(',')->capture_default_str();
  cmd->add_option("--backends", a->backends, "back ends: cpu, cpu-grid, vulkan, rt (each fails softly)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--traversals", a->traversals, "octomap and/or exact")
      ->delimiter(',')
      ->check(CLI::IsMember({"octomap", "exact"}))
      ->capture_default_str();
  cmd->add_option("--octree", a->octrees, "octree stage: sequential and/or batched")
      ->delimiter(',')
      ->check(CLI::IsMember({"sequential", "batched"}))
      ->capture_default_str();
  cmd->add_option("--threads", a->threads, "threads of the CPU stages (0: all hardware threads)")
      ->capture_default_str();
  cmd->add_option("--max-range", a->max_range, "cut rays longer than this [m]; < 0: no limit")->capture_default_str();
  cmd->add_option("--device", a->device, "Vulkan device: name substring or index");
  cmd->add_option("--warmup", a->warmup, "scans inserted into a throw-away map before timing")->capture_default_str();
  cmd->add_option("--repeat", a->repeat, "timed runs per configuration; the median is reported")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--no-octomap-breakdown", a->no_octomap_breakdown,
                "skip the separate computeUpdate pass that splits OctoMap's time into shoot and octree");
  cmd->add_flag("--no-pipeline", a->no_pipeline,
                "run our mappers' two stages one scan after the other (default: scan k+1 is shot while scan k's "
                "octree update runs)");
  cmd->add_option("--prepare", a->prepares,
                  "scan preparation: device (on the GPU where the back end can: vulkan) and/or cpu; "
                  "vulkan's cpu rows are named vulkan/cpu-prep")
      ->delimiter(',')
      ->check(CLI::IsMember({"device", "cpu"}))
      ->capture_default_str();
  cmd->add_option("--csv", a->csv, "write the results as CSV");
  cmd->add_option("--markdown", a->markdown, "write the tables as Markdown (default: to stdout)");
  cmd->add_option("--png", a->png_dir, "write a stage chart per data set (gnuplot) into this folder");
  cmd->add_option("--replot", a->replot, "measure nothing: table and chart these CSV files (e.g. from the GPU machine)")
      ->delimiter(',');
  cmd->callback([a] {
    const int rc = run_bench(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace ort::cli
