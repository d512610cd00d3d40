#include "scene/scan_set.h"

#include <fstream>
#include <iterator>
#include <stdexcept>

#include <octomap/ScanGraph.h>

#include "core/file_checks/scan_graph_check.h"
#include "core/map_frame.h"
#include "core/memory_stream.h"

namespace ort {

size_t ScanSet::total_points() const {
  size_t n = 0;
  for (const auto& s : scans) n += s.points.size();
  return n;
}

ScanSet parse_scan_graph(std::string_view bytes, const std::string& name) {
  // OctoMap's reader asserts on a short cloud and trusts the scan count (see
  // core/file_checks/scan_graph_check.h): the layout is checked first, then OctoMap reads each scan.
  const ScanGraphCheck check = check_scan_graph(bytes);
  if (!check.ok) throw std::runtime_error("'" + name + "' is not a valid OctoMap ScanGraph: " + check.error);
  if (check.scans == 0) throw std::runtime_error("'" + name + "' holds no scans");
  MemoryStream in(bytes);
  uint32_t count = 0;
  in.read(reinterpret_cast<char*>(&count), sizeof count);
  ScanSet set;
  set.name = name;
  for (uint32_t i = 0; i < count; ++i) {
    octomap::ScanNode node;
    node.readBinary(in);
    if (!in) throw std::runtime_error("'" + name + "': OctoMap could not read scan " + std::to_string(i));
    PosedScan s;
    s.pose = node.pose;
    s.points = std::move(*node.scan);
    set.scans.push_back(std::move(s));
  }
  return set;
}

ScanSet load_scan_graph(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open scan graph '" + path + "'");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("cannot read scan graph '" + path + "'");
  return parse_scan_graph(bytes, path);
}

void save_scan_graph(const ScanSet& set, const std::string& path) {
  octomap::ScanGraph graph;
  for (const auto& s : set.scans) graph.addNode(new octomap::Pointcloud(s.points), s.pose);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  graph.writeBinary(out);
  out.close();  // flushes: a full disk shows here
  if (!out) throw std::runtime_error("write to '" + path + "' failed");
}

octomap::Pointcloud world_points(const PosedScan& scan) {
  octomap::Pointcloud pc(scan.points);
  transform_to_map_frame(pc, scan.pose);  // = pc.transform(scan.pose), on several threads
  return pc;
}

}  // namespace ort
