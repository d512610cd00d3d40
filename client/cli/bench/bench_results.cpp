#include "cli/bench/bench_results.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace ort::bench {
namespace {

struct Column {
  std::string name;
  std::function<std::string(const BenchRow&)> get;
  std::function<void(BenchRow&, const std::string&)> set;
};

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// CSV quoting for the free-text fields (device names, error messages).
std::string quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c == '\n' ? ' ' : c;
  }
  return q + "\"";
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"')
        out.back() += '"', ++i;
      else if (c == '"')
        quoted = false;
      else
        out.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else if (c != '\r') {
      out.back() += c;
    }
  }
  return out;
}

#define ORT_TEXT(field)                                                                                               \
  Column {                                                                                                            \
#field, [](const BenchRow& r) { return quote(r.field); }, [](BenchRow & r, const std::string& v) { r.field = v; } \
  }
#define ORT_REAL(field)                                                                                          \
  Column {                                                                                                       \
#field, [](const BenchRow& r) { return num(r.field); }, [](BenchRow & r,                                     \
                                                               const std::string& v) { r.field = std::stod(v); } \
  }
#define ORT_UINT(field)                                                                      \
  Column {                                                                                   \
#field, [](const BenchRow& r) { return std::to_string(r.field); },                         \
        [](BenchRow& r, const std::string& v) { r.field = static_cast<decltype(r.field)>(std::stoull(v)); } \
  }

const std::vector<Column>& columns() {
  static const std::vector<Column> cols = {
      ORT_TEXT(dataset),
      ORT_UINT(scans),
      ORT_UINT(points),
      ORT_REAL(resolution),
      ORT_REAL(max_range),
      ORT_TEXT(backend),
      ORT_TEXT(device),
      ORT_TEXT(traversal),
      ORT_TEXT(octree),
      ORT_TEXT(status),
      ORT_REAL(prepare_ms),
      ORT_REAL(upload_ms),
      ORT_REAL(shoot_ms),
      ORT_REAL(compact_ms),
      ORT_REAL(octree_ms),
      ORT_REAL(total_ms),
      ORT_REAL(octomap_total_ms),
      ORT_REAL(speedup),
      ORT_REAL(points_per_s),
      ORT_UINT(free_voxels),
      ORT_UINT(occupied_voxels),
      ORT_UINT(octomap_free),
      ORT_UINT(octomap_occupied),
      ORT_REAL(free_diff_pct),
      ORT_REAL(occupied_diff_pct),
      ORT_TEXT(counts_equal),
      ORT_TEXT(map_identical),
      ORT_UINT(tree_bytes),
      ORT_UINT(rss_bytes),
      ORT_UINT(peak_rss_bytes),
      ORT_UINT(gpu_grid_bytes),
      ORT_UINT(windows),
      ORT_UINT(voxel_updates),
      ORT_UINT(warmup_scans),
      ORT_UINT(repeats),
  };
  return cols;
}

std::string label(const BenchRow& r) {
  std::string l = r.backend;
  if (r.backend != "octomap" && r.traversal == "exact") l += "/exact";
  if (r.backend != "octomap" && r.octree == "batched") l += "+batched";
  return l;
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

double mib(uint64_t b) { return double(b) / (1024.0 * 1024.0); }

// Rows grouped by (dataset, resolution) in order of appearance.
std::vector<std::vector<const BenchRow*>> groups(const std::vector<BenchRow>& rows) {
  std::vector<std::vector<const BenchRow*>> g;
  std::map<std::pair<std::string, double>, size_t> index;
  for (const BenchRow& r : rows) {
    const auto key = std::make_pair(r.dataset, r.resolution);
    auto it = index.find(key);
    if (it == index.end()) {
      index[key] = g.size();
      g.push_back({&r});
    } else {
      g[it->second].push_back(&r);
    }
  }
  return g;
}

}  // namespace

const std::vector<std::string>& csv_columns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Column& c : columns()) n.push_back(c.name);
    return n;
  }();
  return names;
}

void write_csv(const std::vector<BenchRow>& rows, std::ostream& out) {
  const auto& cols = columns();
  for (size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << cols[i].name;
  out << "\n";
  for (const BenchRow& r : rows) {
    for (size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << cols[i].get(r);
    out << "\n";
  }
}

std::vector<BenchRow> read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error("'" + path + "' is empty");
  const std::vector<std::string> header = split_csv_line(line);
  std::vector<const Column*> by_position;
  for (const std::string& h : header) {
    const Column* found = nullptr;
    for (const Column& c : columns())
      if (c.name == h) found = &c;
    by_position.push_back(found);  // unknown columns (a newer bench) are ignored
  }
  std::vector<BenchRow> rows;
  for (size_t n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::vector<std::string> f = split_csv_line(line);
    if (f.size() != header.size())
      throw std::runtime_error(path + ":" + std::to_string(n) + ": " + std::to_string(f.size()) +
                               " fields, header has " + std::to_string(header.size()));
    BenchRow r;
    for (size_t i = 0; i < f.size(); ++i) {
      if (!by_position[i]) continue;
      try {
        by_position[i]->set(r, f[i]);
      } catch (const std::exception&) {
        throw std::runtime_error(path + ":" + std::to_string(n) + ": bad value '" + f[i] + "' for " + header[i]);
      }
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

void write_markdown(const std::vector<BenchRow>& rows, std::ostream& out) {
  const auto g = groups(rows);
  // Mapper labels of octomap-traversal runs, in order of appearance: the headline columns.
  std::vector<std::string> mappers;
  for (const BenchRow& r : rows) {
    if (r.backend == "octomap" || r.traversal != "octomap" || r.status != "ok") continue;  // failures: listed below
    const std::string l = label(r);
    if (std::find(mappers.begin(), mappers.end(), l) == mappers.end()) mappers.push_back(l);
  }

  out << "**End to end** (wall clock over all scans, transform into the map frame included; ratio = OctoMap's "
         "time / ours, measured in the same run; = : the map is identical to OctoMap's, leaf for leaf)\n\n";
  out << "| data set | scans | points | res [m] | OctoMap [s] |";
  for (const auto& m : mappers) out << " " << m << " [s] |";
  out << "\n|---|---:|---:|---:|---:|";
  for (size_t i = 0; i < mappers.size(); ++i) out << "---:|";
  out << "\n";
  for (const auto& grp : g) {
    const BenchRow* ref = nullptr;
    for (const BenchRow* r : grp)
      if (r->backend == "octomap") ref = r;
    const BenchRow& f = *grp.front();
    out << "| " << f.dataset << " | " << f.scans << " | " << f.points << " | " << num(f.resolution) << " | "
        << (ref ? fixed(ref->total_ms / 1000.0, 2) : "-") << " |";
    for (const auto& m : mappers) {
      const BenchRow* hit = nullptr;
      for (const BenchRow* r : grp)
        if (r->backend != "octomap" && r->traversal == "octomap" && label(*r) == m) hit = r;
      if (!hit)
        out << " - |";
      else if (hit->status != "ok")
        out << " n/a |";
      else
        out << " " << fixed(hit->total_ms / 1000.0, 2) << " (**" << fixed(hit->speedup, 1) << "x**"
            << (hit->map_identical == "yes"  ? ", ="
                : hit->counts_equal == "yes" ? ", counts ="
                                             : ", DIFFERENT")
            << ") |";
    }
    out << "\n";
  }

  out << "\n**Stage breakdown** (paper Fig. 6; ms summed over all scans. OctoMap: prepare = transform, shoot = "
         "computeUpdate timed in a separate pass, octree = the rest of insertPointCloud)\n\n";
  out << "| data set | res [m] | mapper | prepare | upload | shoot | compact+readback | octree | total |\n"
         "|---|---:|---|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& grp : g)
    for (const BenchRow* r : grp) {
      if (r->status != "ok" || (r->backend != "octomap" && r->traversal != "octomap")) continue;
      out << "| " << r->dataset << " | " << num(r->resolution) << " | " << label(*r) << " | " << fixed(r->prepare_ms, 1)
          << " | " << fixed(r->upload_ms, 1) << " | " << fixed(r->shoot_ms, 1) << " | " << fixed(r->compact_ms, 1)
          << " | " << fixed(r->octree_ms, 1) << " | " << fixed(r->total_ms, 1) << " |\n";
    }

  out << "\n**Accuracy** (paper Fig. 10: finest-level voxels, ours against OctoMap's; the paper reports "
         "+0.65% free and -0.59% occupied for its geometric traversal)\n\n";
  out << "| data set | res [m] | mapper | traversal | free (ours / OctoMap) | occupied (ours / OctoMap) | free diff | "
         "occupied diff | identical map |\n|---|---:|---|---|---:|---:|---:|---:|---|\n";
  for (const auto& grp : g)
    for (const BenchRow* r : grp) {
      if (r->status != "ok" || r->backend == "octomap") continue;
      out << "| " << r->dataset << " | " << num(r->resolution) << " | " << label(*r) << " | " << r->traversal << " | "
          << r->free_voxels << " / " << r->octomap_free << " | " << r->occupied_voxels << " / " << r->octomap_occupied
          << " | " << (r->free_diff_pct >= 0 ? "+" : "") << fixed(r->free_diff_pct, 2) << "% | "
          << (r->occupied_diff_pct >= 0 ? "+" : "") << fixed(r->occupied_diff_pct, 2) << "% | " << r->map_identical
          << " |\n";
    }

  out << "\n**Memory** (tree: OcTree::memoryUsage; RSS: process resident set after the run, peak: process peak "
         "so far; grid: the persistent shared ray space)\n\n";
  out << "| data set | res [m] | mapper | tree [MiB] | RSS [MiB] | peak RSS [MiB] | grid [MiB] | windows |\n"
         "|---|---:|---|---:|---:|---:|---:|---:|\n";
  for (const auto& grp : g)
    for (const BenchRow* r : grp) {
      if (r->status != "ok" || (r->backend != "octomap" && r->traversal != "octomap")) continue;
      out << "| " << r->dataset << " | " << num(r->resolution) << " | " << label(*r) << " | "
          << fixed(mib(r->tree_bytes), 1) << " | " << fixed(mib(r->rss_bytes), 0) << " | "
          << fixed(mib(r->peak_rss_bytes), 0) << " | " << fixed(mib(r->gpu_grid_bytes), 1) << " | " << r->windows
          << " |\n";
    }
  bool any_failed = false;
  for (const BenchRow& r : rows) any_failed = any_failed || r.status != "ok";
  if (any_failed) {
    // One line per (mapper, reason), with the runs it covers: the same reason repeats for
    // every data set and resolution.
    std::vector<std::pair<std::string, std::string>> reasons;  // (mapper, status)
    std::map<std::pair<std::string, std::string>, std::string> runs;
    for (const BenchRow& r : rows) {
      if (r.status == "ok") continue;
      const auto key = std::make_pair(label(r) + " (" + r.traversal + ")", r.status);
      if (!runs.count(key)) reasons.push_back(key);
      runs[key] += (runs[key].empty() ? "" : ", ") + r.dataset + " @ " + num(r.resolution) + " m";
    }
    out << "\n**Not measured**\n\n";
    for (const auto& key : reasons) {
      std::string why = key.second;
      for (char& c : why)
        if (c == '\n') c = ' ';
      out << "- " << key.first << ": " << why << " [" << runs[key] << "]\n";
    }
  }
}

}  // namespace ort::bench
