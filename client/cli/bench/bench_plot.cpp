#include "cli/bench/bench_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

namespace ort::bench {
namespace {

// A file-name-safe form of a data set name (a preset name, or a .graph path).
std::string slug(const std::string& dataset) {
  std::string s = std::filesystem::path(dataset).filename().string();
  if (s.size() > 6 && s.compare(s.size() - 6, 6, ".graph") == 0) s.resize(s.size() - 6);
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return s.empty() ? "dataset" : s;
}

std::string bar_label(const BenchRow& r) {
  if (r.backend == "octomap") return "OctoMap";
  std::string l = r.backend;
  if (r.octree == "batched") l += "+batched";
  return l;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

bool plot_stage_charts(const std::vector<BenchRow>& rows, const std::string& dir, std::string& message) {
  std::filesystem::create_directories(dir);
  // dataset -> resolution -> bars (octomap traversal only: the mappers that build OctoMap's map)
  std::vector<std::string> order;
  std::map<std::string, std::map<double, std::vector<const BenchRow*>>> by;
  for (const BenchRow& r : rows) {
    if (r.status != "ok" || (r.backend != "octomap" && r.traversal != "octomap")) continue;
    if (!by.count(r.dataset)) order.push_back(r.dataset);
    by[r.dataset][r.resolution].push_back(&r);
  }
  const bool have_gnuplot = std::system("gnuplot --version > /dev/null 2>&1") == 0;
  bool ok = have_gnuplot;
  message = have_gnuplot ? "" : "gnuplot not found: wrote the .dat and .gp files only";
  static const char* kStages[] = {"prepare", "upload", "shoot", "compact+readback", "octree"};
  static const char* kColours[] = {"#9e9e9e", "#f2c14e", "#2a9d8f", "#5fa8d3", "#e76f51"};
  for (const std::string& ds : order) {
    const std::string base = slug(ds);
    const std::string dat = dir + "/" + base + ".dat", gp = dir + "/" + base + ".gp";
    // gnuplot refuses log scale on its stacked histograms, so the stacks are drawn as boxes:
    // the file holds each bar's cumulative stage bounds.
    double smallest = std::numeric_limits<double>::infinity(), largest = 0;
    std::vector<std::pair<double, std::string>> groups;  // centre x, "0.1 m"
    {
      std::ofstream d(dat);
      d << "# x label then, per stage (prepare upload shoot compact+readback octree), its bottom and top [ms]\n";
      double x = 0;
      for (const auto& [res, bars] : by[ds]) {
        const double first = x;
        for (const BenchRow* r : bars) {
          const double v[5] = {r->prepare_ms, r->upload_ms, r->shoot_ms, r->compact_ms, r->octree_ms};
          d << x << " \"" << bar_label(*r) << '"';
          double cum = 0;
          for (double t : v) {
            d << ' ' << cum << ' ' << cum + t;
            cum += t;
            if (t > 0) smallest = std::min(smallest, t);
          }
          largest = std::max(largest, cum);
          d << "\n";
          x += 1;
        }
        char name[32];
        std::snprintf(name, sizeof name, "%g m", res);
        groups.push_back({0.5 * (first + x - 1), name});
        x += 1;  // a gap between resolutions
      }
    }
    if (!(smallest < largest)) smallest = largest / 10;
    const double ymin = std::pow(10.0, std::floor(std::log10(std::max(smallest, 1e-3))));
    std::ofstream s(gp);
    s << "# Stage times of " << ds << " (octomap-rt bench), log scale like the paper's Fig. 6.\n"
      << "set terminal pngcairo size 1280,640 font ',10'\n"
      << "set output '" << base << ".png'\n"
      << "set title \"" << ds << ": time per stage over all scans, per mapper and resolution (log scale)\"\n"
      << "set logscale y\nset yrange [" << ymin << ":" << largest * 3 << "]\n"
      << "set ylabel 'time [ms]'\nset grid ytics\nset key outside right top\n"
      << "set xtics rotate by -30 scale 0 nomirror\nset style fill solid 0.9 border rgb 'black'\n"
      << "set bmargin 6\n";
    for (const auto& [gx, name] : groups)
      s << "set label '" << name << "' at " << gx << ", graph -0.14 center font ',11'\n";
    s << "bottom(v) = v > " << ymin << " ? v : " << ymin << "\n";
    s << "plot";
    for (int k = 0; k < 5; ++k) {
      const int lo = 3 + 2 * k, hi = lo + 1;
      // the bottom stage starts at the axis (log scale has no zero)
      s << (k ? ", \\\n    " : " ") << "'" << base << ".dat' using 1:(column(" << hi << ")):($1-0.4):($1+0.4):"
        << "(bottom(column(" << lo << "))):(column(" << hi << "))" << (k == 0 ? ":xtic(2)" : "")
        << " with boxxyerror title '" << kStages[k] << "' lc rgb '" << kColours[k] << "'";
    }
    s << "\n";
    s.close();
    if (have_gnuplot) {
      const std::string cmd = "cd " + shell_quote(dir) + " && gnuplot " + shell_quote(base + ".gp") + " 2>&1";
      if (std::system(cmd.c_str()) != 0) {
        ok = false;
        message += "gnuplot failed on " + gp + "; ";
      }
    }
  }
  return ok;
}

}  // namespace ort::bench
