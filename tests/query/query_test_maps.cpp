#include "query_test_maps.h"

#include <array>
#include <map>
#include <memory>

#include <gtest/gtest.h>

#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

std::unique_ptr<octomap::OcTree> load_bt(const std::string& path) {
  auto t = std::make_unique<octomap::OcTree>(0.1);
  if (path.empty() || !t->readBinary(path)) ADD_FAILURE() << "cannot read " << path;
  return t;
}

std::unique_ptr<octomap::OcTree> build(const std::string& graph, double res, double max_range) {
  if (graph.empty()) return std::make_unique<octomap::OcTree>(res);
  return octomap_reference(load_scan_graph(graph), res, max_range);
}

}  // namespace

const std::vector<NamedMap>& query_test_maps() {
  static const auto geb = load_bt(data_file("octomap_share/geb079.bt"));
  static const auto dtk = build(data_file("3dtk_dat/3dtk_3scans.graph"), 0.2, 30.0);
  static const auto fr = build(data_file("octomap_share/scan_dat.graph"), 0.1, 10.0);
  static const std::vector<NamedMap> maps = {
      {"geb079.bt", geb.get()}, {"3dtk 0.2 m", dtk.get()}, {"scan_dat 0.1 m", fr.get()}};
  return maps;
}

void map_extent(const octomap::OcTree& t, double margin, double lo[3], double hi[3]) {
  // OcTree's const getMetricMin/Max walk every leaf on each call: once per tree here.
  static std::map<const octomap::OcTree*, std::array<double, 6>> known;
  auto it = known.find(&t);
  if (it == known.end()) {
    std::array<double, 6> e;
    t.getMetricMin(e[0], e[1], e[2]);
    t.getMetricMax(e[3], e[4], e[5]);
    it = known.emplace(&t, e).first;
  }
  for (int i = 0; i < 3; ++i) lo[i] = it->second[i] - margin, hi[i] = it->second[i + 3] + margin;
}

octomap::point3d random_point(const octomap::OcTree& t, std::mt19937& rng) {
  double lo[3], hi[3];
  map_extent(t, 2.0, lo, hi);
  const double res = t.getResolution();
  std::uniform_real_distribution<double> u(0, 1);
  float p[3];
  const int kind = std::uniform_int_distribution<int>(0, 9)(rng);
  for (int i = 0; i < 3; ++i) {
    double v = lo[i] + u(rng) * (hi[i] - lo[i]);
    if (kind == 0) v = (hi[i] + 100.0) * (u(rng) < 0.5 ? -1 : 1) * 10;    // far outside
    if (kind == 1) v = (u(rng) < 0.5 ? -1 : 1) * (32768 * res + u(rng));  // beyond the key range
    if (kind >= 2 && kind <= 4) v = std::round(v / res) * res;            // on voxel faces
    p[i] = static_cast<float>(v);
  }
  return octomap::point3d(p[0], p[1], p[2]);
}

}  // namespace ort::test
