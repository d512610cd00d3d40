// `octomap-rt bench` results: one row per (data set, resolution, mapper), written as CSV and
// read back (so that a CSV measured on the GPU machine can be charted and tabled here).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace ort::bench {

// A mapper is OctoMap itself (backend "octomap", the reference) or one engine configuration
// (back end x traversal x octree stage).
struct BenchRow {
  std::string dataset;
  uint64_t scans = 0, points = 0;
  double resolution = 0, max_range = -1;
  std::string backend, device, traversal, octree;
  std::string status = "ok";  // "ok", or why this mapper could not run
  // Stage times summed over the scans [ms] (paper Fig. 6). For OctoMap: prepare = transform
  // into the map frame, shoot = computeUpdate (ray keys + KeySets, timed in a separate pass),
  // octree = insertPointCloud minus that.
  double prepare_ms = 0, upload_ms = 0, shoot_ms = 0, compact_ms = 0, octree_ms = 0;
  double total_ms = 0;          // wall clock of the whole run, transform included
  double octomap_total_ms = 0;  // OctoMap's total in the same process, same data
  double speedup = 0;           // octomap_total_ms / total_ms
  double points_per_s = 0;
  // Leaf counts at the finest level (paper Fig. 10), ours and OctoMap's.
  uint64_t free_voxels = 0, occupied_voxels = 0, octomap_free = 0, octomap_occupied = 0;
  double free_diff_pct = 0, occupied_diff_pct = 0;
  std::string counts_equal;   // "yes" / "no" (finest-level free and occupied counts)
  std::string map_identical;  // "yes" / "no": same leaves, depths and log-odds as OctoMap's tree
  // Memory.
  uint64_t tree_bytes = 0;      // OcTree::memoryUsage()
  uint64_t rss_bytes = 0;       // process resident set after the run (tree alive)
  uint64_t peak_rss_bytes = 0;  // process peak so far (monotonic over the whole bench)
  uint64_t gpu_grid_bytes = 0;  // the shared ray space: ShootStats::grid_words * 4
  uint64_t windows = 0, voxel_updates = 0;
  int warmup_scans = 0, repeats = 1;
};

void write_csv(const std::vector<BenchRow>& rows, std::ostream& out);
// Throws std::runtime_error when the file is missing or a row is malformed.
std::vector<BenchRow> read_csv(const std::string& path);
// The column names, in CSV order (for the smoke test and for readers).
const std::vector<std::string>& csv_columns();

// Markdown tables: headline ratios, stage breakdown, accuracy (Fig. 10), memory.
void write_markdown(const std::vector<BenchRow>& rows, std::ostream& out);

}  // namespace ort::bench
