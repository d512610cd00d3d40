// `octomap-rt bench` on a tiny preset: the CSV is well formed (every column, one OctoMap row
// per resolution, finite ratios and times) and octomap-mode runs reproduce OctoMap's map.
// No timing assertions: speed is what the benchmark reports, not what a test checks.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace ort::test {
namespace {

// A plain CSV reader written for this test (quotes, commas inside quotes), so that a bug in
// the bench's own reader cannot hide a malformed file.
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> f(1);
  bool q = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (q && c == '"' && i + 1 < line.size() && line[i + 1] == '"')
      f.back() += '"', ++i;
    else if (c == '"')
      q = !q;
    else if (c == ',' && !q)
      f.emplace_back();
    else
      f.back() += c;
  }
  return f;
}

using Row = std::map<std::string, std::string>;

std::vector<Row> read(const std::string& path, std::vector<std::string>& header) {
  std::ifstream in(path);
  std::string line;
  std::vector<Row> rows;
  if (!std::getline(in, line)) return rows;
  header = split(line);
  while (std::getline(in, line)) {
    const auto f = split(line);
    EXPECT_EQ(f.size(), header.size()) << line;
    Row r;
    for (size_t i = 0; i < f.size() && i < header.size(); ++i) r[header[i]] = f[i];
    rows.push_back(r);
  }
  return rows;
}

double number(const Row& r, const std::string& col) {
  const std::string& v = r.at(col);
  size_t used = 0;
  const double d = std::stod(v, &used);
  EXPECT_EQ(used, v.size()) << col << " = '" << v << "'";
  return d;
}

TEST(BenchSmoke, TinyPresetGivesAWellFormedCsv) {
  const std::string dir = testing::TempDir() + "/bench_smoke";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/bench.csv", md = dir + "/bench.md";
  const std::string cmd = std::string(OCTOMAP_RT_CLI) +
                          " bench --preset fr079 --scale ci --resolutions 0.2,0.8 --backends cpu,cpu-grid,vulkan"
                          " --traversals octomap,exact --csv " +
                          csv + " --markdown " + md + " --png " + dir + "/charts 2> " + dir + "/stderr.txt";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << "\n(see " << dir << "/stderr.txt)";

  std::vector<std::string> header;
  const auto rows = read(csv, header);
  for (const char* col :
       {"dataset",      "scans",           "points",       "resolution",       "backend",        "device",
        "traversal",    "octree",          "status",       "prepare_ms",       "upload_ms",      "shoot_ms",
        "compact_ms",   "octree_ms",       "total_ms",     "octomap_total_ms", "speedup",        "points_per_s",
        "free_voxels",  "occupied_voxels", "octomap_free", "octomap_occupied", "free_diff_pct",  "occupied_diff_pct",
        "counts_equal", "map_identical",   "tree_bytes",   "rss_bytes",        "peak_rss_bytes", "gpu_grid_bytes"})
    EXPECT_NE(std::find(header.begin(), header.end(), col), header.end()) << "column " << col << " missing";
  // 2 resolutions x (OctoMap + 3 back ends x 2 traversals)
  ASSERT_EQ(rows.size(), 2u * (1 + 3 * 2));

  int octomap_rows = 0, octomap_mode_runs = 0, exact_runs = 0;
  for (const Row& r : rows) {
    EXPECT_EQ(r.at("dataset"), "fr079");
    EXPECT_GT(number(r, "points"), 0);
    if (r.at("backend") == "octomap") {
      ++octomap_rows;
      EXPECT_EQ(r.at("status"), "ok");
      EXPECT_GT(number(r, "octomap_free") + number(r, "octomap_occupied"), 0);
      continue;
    }
    // vulkan may be unavailable on a machine without any Vulkan device: it must say so.
    if (r.at("status") != "ok") {
      EXPECT_EQ(r.at("backend"), "vulkan") << r.at("status");
      EXPECT_EQ(r.at("status").rfind("unavailable: ", 0), 0u) << r.at("status");
      continue;
    }
    for (const char* col : {"prepare_ms", "upload_ms", "shoot_ms", "compact_ms", "octree_ms", "total_ms",
                            "octomap_total_ms", "speedup", "points_per_s", "free_diff_pct", "occupied_diff_pct"}) {
      const double v = number(r, col);
      EXPECT_TRUE(std::isfinite(v)) << col;
      if (std::string(col).find("diff") == std::string::npos) {
        EXPECT_GE(v, 0) << col;
      }
    }
    EXPECT_GT(number(r, "speedup"), 0);
    EXPECT_NEAR(number(r, "speedup"), number(r, "octomap_total_ms") / number(r, "total_ms"),
                1e-3 * number(r, "speedup"));
    if (r.at("traversal") == "octomap") {
      ++octomap_mode_runs;
      EXPECT_EQ(r.at("free_voxels"), r.at("octomap_free")) << r.at("backend");
      EXPECT_EQ(r.at("occupied_voxels"), r.at("octomap_occupied")) << r.at("backend");
      EXPECT_EQ(r.at("counts_equal"), "yes");
      EXPECT_EQ(r.at("map_identical"), "yes") << r.at("backend") << " @ " << r.at("resolution");
    } else {
      ++exact_runs;
      // exact mode marks a superset of OctoMap's free voxels along each ray
      EXPECT_GT(number(r, "free_voxels"), 0);
    }
  }
  EXPECT_EQ(octomap_rows, 2);
  EXPECT_GE(octomap_mode_runs, 4);  // cpu and cpu-grid at both resolutions at least
  EXPECT_GE(exact_runs, 4);

  std::ifstream m(md);
  const std::string text((std::istreambuf_iterator<char>(m)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| fr079 |"), std::string::npos);
  EXPECT_NE(text.find("**Accuracy**"), std::string::npos);

  // --replot reads the CSV back and tables it the same way
  const std::string md2 = dir + "/replot.md";
  ASSERT_EQ(std::system((std::string(OCTOMAP_RT_CLI) + " bench --replot " + csv + " --markdown " + md2).c_str()), 0);
  std::ifstream m2(md2);
  const std::string text2((std::istreambuf_iterator<char>(m2)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, text2);
  if (std::system("gnuplot --version > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/charts/fr079.png"));
  }
}

}  // namespace
}  // namespace ort::test
