#include "scene/scan_set.h"

#include <fstream>
#include <stdexcept>

#include <octomap/ScanGraph.h>

#include "core/map_frame.h"

namespace ort {

size_t ScanSet::total_points() const {
  size_t n = 0;
  for (const auto& s : scans) n += s.points.size();
  return n;
}

ScanSet load_scan_graph(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open scan graph '" + path + "'");
  octomap::ScanGraph graph;
  graph.readBinary(in);
  if (!in && !in.eof()) throw std::runtime_error("'" + path + "' is not a readable OctoMap ScanGraph");
  if (graph.size() == 0) throw std::runtime_error("'" + path + "' holds no scans");
  ScanSet set;
  set.name = path;
  for (auto it = graph.begin(); it != graph.end(); ++it) {
    PosedScan s;
    s.pose = (*it)->pose;
    s.points = *(*it)->scan;
    set.scans.push_back(std::move(s));
  }
  return set;
}

void save_scan_graph(const ScanSet& set, const std::string& path) {
  octomap::ScanGraph graph;
  for (const auto& s : set.scans) graph.addNode(new octomap::Pointcloud(s.points), s.pose);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  graph.writeBinary(out);
  if (!out) throw std::runtime_error("write to '" + path + "' failed");
}

octomap::Pointcloud world_points(const PosedScan& scan) {
  octomap::Pointcloud pc(scan.points);
  transform_to_map_frame(pc, scan.pose);  // = pc.transform(scan.pose), on several threads
  return pc;
}

}  // namespace ort
