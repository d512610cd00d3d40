#include "scene/scan_set.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
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

namespace {

// The pages of a read-only file mapping from `from` up to `to` (rounded inward to whole
// pages) dropped from the process's resident set: they come back from the page cache if read
// again. A hint; a refusal changes nothing.
void drop_pages(const char* base, size_t from, size_t to) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  const size_t a = (from + page - 1) / page * page, b = to / page * page;
  if (b > a) madvise(const_cast<char*>(base) + a, b - a, MADV_DONTNEED);
}

// parse_scan_graph's body. OctoMap's reader asserts on a short cloud and trusts the scan
// count (see core/file_checks/scan_graph_check.h): the layout is checked first, then OctoMap
// reads each scan. `mapped` (a file mapping): the pages of each scan read are dropped.
ScanSet parse_checked(std::string_view bytes, const std::string& name, bool mapped) {
  const ScanGraphCheck check = check_scan_graph(bytes);
  if (!check.ok) throw std::runtime_error("'" + name + "' is not a valid OctoMap ScanGraph: " + check.error);
  if (check.scans == 0) throw std::runtime_error("'" + name + "' holds no scans");
  if (mapped) drop_pages(bytes.data(), 0, bytes.size());
  MemoryStream in(bytes);
  uint32_t count = 0;
  in.read(reinterpret_cast<char*>(&count), sizeof count);
  ScanSet set;
  set.name = name;
  size_t dropped = 0;
  for (uint32_t i = 0; i < count; ++i) {
    octomap::ScanNode node;
    node.readBinary(in);
    if (!in) throw std::runtime_error("'" + name + "': OctoMap could not read scan " + std::to_string(i));
    PosedScan s;
    s.pose = node.pose;
    s.points = std::move(*node.scan);
    set.scans.push_back(std::move(s));
    if (mapped) {
      const size_t at = size_t(in.tellg());
      drop_pages(bytes.data(), dropped, at);
      dropped = at;
    }
  }
  return set;
}

}  // namespace

ScanSet parse_scan_graph(std::string_view bytes, const std::string& name) { return parse_checked(bytes, name, false); }

// The file is mapped, not read into memory: the checked bytes of each scan leave the resident
// set once its points are parsed, so a large .graph (28 bytes a point on disk, 12 in memory)
// costs its points, not the file and its points (issue 25: peak memory beside graph2tree's).
ScanSet load_scan_graph(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open scan graph '" + path + "'");
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    ::close(fd);
    throw std::runtime_error("cannot read scan graph '" + path + "'");
  }
  const size_t size = size_t(st.st_size);
  if (size == 0) {
    ::close(fd);
    return parse_checked(std::string_view(), path, false);
  }
  void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) throw std::runtime_error("cannot map scan graph '" + path + "'");
  struct Unmap {
    void* p;
    size_t n;
    ~Unmap() { ::munmap(p, n); }
  } unmap{p, size};
  return parse_checked(std::string_view(static_cast<const char*>(p), size), path, true);
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
