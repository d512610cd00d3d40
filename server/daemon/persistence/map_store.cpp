#include "daemon/persistence/map_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <utility>

#include "core/clock.h"
#include "core/file_checks/bt_file.h"
#include "core/file_checks/octree_file_check.h"
#include "daemon/persistence/map_identity_file.h"

namespace ort::daemon {
namespace {

using Kind = MapStoreError::Kind;

MapStoreError sys_error(Kind kind, const std::string& what, const std::string& path) {
  return MapStoreError(kind, what + " '" + path + "': " + std::strerror(errno));
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string directory_of(const std::string& path) {
  std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? "." : dir;
}

void write_all(int fd, std::string_view bytes, const std::string& path) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw sys_error(Kind::kWrite, "cannot write", path);
    done += static_cast<size_t>(n);
  }
}

// Writes, fsyncs and closes `path` (created new or truncated).
void write_and_sync(const std::string& path, std::string_view bytes, int extra_flags) {
  Fd f;
  f.fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | extra_flags, 0644);
  if (f.fd < 0) throw sys_error(Kind::kWrite, "cannot create", path);
  write_all(f.fd, bytes, path);
  if (::fsync(f.fd) != 0) throw sys_error(Kind::kSync, "cannot fsync", path);
  const int fd = f.fd;
  f.fd = -1;
  if (::close(fd) != 0) throw sys_error(Kind::kWrite, "cannot close", path);
}

void sync_directory(const std::string& dir) {
  Fd d;
  d.fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (d.fd < 0 || ::fsync(d.fd) != 0) throw sys_error(Kind::kSync, "cannot fsync directory", dir);
}

// Read at its size (no doubling growth: a large map's bytes are held once).
std::string read_whole(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw sys_error(Kind::kOpen, "cannot open map", path);
  const std::streamoff size = in.tellg();
  if (size < 0) throw sys_error(Kind::kRead, "cannot read map", path);
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(0);
  in.read(bytes.data(), size);
  if (in.bad() || in.gcount() != size) throw sys_error(Kind::kRead, "cannot read map", path);
  return bytes;
}

// The header prints the resolution as text (6 significant digits), so allow for that
// rounding, and then use the requested value bit for bit.
void require_resolution(octomap::OcTree& tree, double resolution, const std::string& path, const char* flag) {
  const double file_res = tree.getResolution();
  if (std::abs(file_res - resolution) > 1e-6 * resolution) {
    std::ostringstream msg;
    msg << "map '" << path << "' has resolution " << file_res << " m but the server was started with -r " << resolution
        << "; start with -r " << file_res << " (or without -r: the file's), or use another " << flag << " file";
    throw MapStoreError(Kind::kWrongResolution, msg.str());
  }
  if (file_res != resolution) tree.setResolution(resolution);
}

std::string utc_stamp() { return utc_text("%Y%m%dT%H%M%SZ"); }

}  // namespace

const char* to_string(MapStoreError::Kind kind) {
  switch (kind) {
    case Kind::kOpen: return "cannot open";
    case Kind::kRead: return "cannot read";
    case Kind::kCorrupt: return "corrupt map file";
    case Kind::kWrongType: return "not an OcTree";
    case Kind::kWrongResolution: return "wrong resolution";
    case Kind::kWrite: return "write failed";
    case Kind::kSync: return "fsync failed";
    case Kind::kRename: return "rename failed";
    case Kind::kNotWritable: return "map directory not writable";
    case Kind::kSerialize: return "cannot serialize";
    case Kind::kLocked: return "map in use";
  }
  return "unknown";
}

std::string serialize_map(const octomap::OcTree& tree) {
  std::ostringstream out(std::ios::binary);
  if (!tree.write(out)) throw MapStoreError(Kind::kSerialize, "could not serialize the map");
  return std::move(out).str();
}

std::unique_ptr<octomap::OcTree> load_map(const std::string& path, double resolution) {
  return load_map_file(path, resolution).tree;
}

namespace {

// A checked .ot file's regions past the bound go to its spill, and `bytes` becomes the file
// of the tree that stays (the whole file's bytes are dropped before any tree is built).
MapFileSplit keep_within_bound(std::string& bytes, size_t data_offset, const MapLoadBound& bound,
                               const std::string& what) {
  MapFileSplit split;
  try {
    split = split_map_file(bytes, data_offset, bound.grid, bound.keep_bytes, bound.spill);
  } catch (const MapStoreError&) {
    throw;
  } catch (const std::runtime_error& e) {  // the spill refused (the region store says why) or the data
    throw MapStoreError(Kind::kRead, what + " could not be loaded within the memory bound: " + e.what());
  }
  bytes = std::move(split.kept);
  return split;
}

}  // namespace

LoadedMapFile load_map_file(const std::string& path, double resolution, const MapLoadBound* bound) {
  std::string bytes = read_whole(path);
  const OctreeFileCheck check = check_octree_file(bytes, /*inner_is_max=*/true);
  if (!check.ok) {
    const bool other_tree = !check.tree_type.empty() && check.tree_type != "OcTree";
    const Kind kind = other_tree ? Kind::kWrongType : Kind::kCorrupt;
    throw MapStoreError(kind, "map '" + path + "' is not a complete OctoMap .ot file: " + check.error);
  }
  if (check.format != OctreeFileFormat::kFull)
    throw MapStoreError(Kind::kWrongType, "map '" + path +
                                              "' is a .bt file (no log-odds); the map of record is kept as .ot: "
                                              "start from it with --prior and save to another --map");
  LoadedMapFile loaded;
  loaded.bytes = bytes.size();
  loaded.hash = map_file_hash(bytes);
  if (bound) {
    const MapFileSplit split = keep_within_bound(bytes, check.data_offset, *bound, "map '" + path + "'");
    loaded.spilled_regions = split.spilled_regions;
    loaded.spilled_nodes = split.spilled_nodes;
  }
  try {
    loaded.tree = read_octree_file_bytes(bytes, "map '" + path + "'", /*inner_is_max=*/true);
  } catch (const std::runtime_error& e) {
    // The file was checked whole above: a kept part that does not read is this server's
    // fault, not the file's (never moved aside as corrupt; regions already went to the spill).
    throw MapStoreError(bound ? Kind::kRead : Kind::kCorrupt,
                        bound ? std::string("the part within the memory bound did not read: ") + e.what() : e.what());
  }
  require_resolution(*loaded.tree, resolution, path, "--map");
  return loaded;
}

std::unique_ptr<octomap::OcTree> load_prior_map(const std::string& path, double resolution, const SensorModel& sensor,
                                                const MapLoadBound* bound) {
  std::string bytes = read_whole(path);
  const OctreeFileCheck check = check_octree_file(bytes);
  if (!check.ok) {
    const bool other_tree = !check.tree_type.empty() && check.tree_type != "OcTree";
    throw MapStoreError(other_tree ? Kind::kWrongType : Kind::kCorrupt,
                        "prior map '" + path + "' is not a complete OctoMap OcTree file (.bt or .ot): " + check.error);
  }
  // A .ot prior is split like the map file; a .bt one is first turned into the .ot readBinary
  // and the value rule below would make of it (core/file_checks/bt_file.h), then split the same way.
  const bool binary = check.format == OctreeFileFormat::kBinary;
  bool values_set = false;
  if (bound && binary) {
    try {
      bytes = ot_file_from_bt(bytes, check.data_offset, octomap::logodds(sensor.clamping_max),
                              octomap::logodds(sensor.clamping_min));
    } catch (const std::runtime_error& e) {
      throw MapStoreError(Kind::kCorrupt, "prior map '" + path + "': " + e.what());
    }
    const OctreeFileCheck ot = check_octree_file(bytes);
    if (!ot.ok) throw MapStoreError(Kind::kCorrupt, "prior map '" + path + "' as .ot: " + ot.error);
    keep_within_bound(bytes, ot.data_offset, *bound, "prior map '" + path + "'");
    values_set = true;
  } else if (bound) {
    keep_within_bound(bytes, check.data_offset, *bound, "prior map '" + path + "'");
  }
  std::unique_ptr<octomap::OcTree> tree;
  try {
    tree = read_octree_file_bytes(bytes, "prior map '" + path + "'");
  } catch (const std::runtime_error& e) {
    throw MapStoreError(Kind::kCorrupt, e.what());
  }
  require_resolution(*tree, resolution, path, "--prior");
  if (binary && !values_set) {
    // readBinary gave every node OctoMap's default clamping bounds: move them to this sensor
    // model's (a monotonic map, so inner nodes stay their children's maximum).
    const float occupied = octomap::logodds(sensor.clamping_max), free = octomap::logodds(sensor.clamping_min);
    for (auto it = tree->begin_tree(), end = tree->end_tree(); it != end; ++it)
      it->setLogOdds(tree->isNodeOccupied(*it) ? occupied : free);
  }
  apply_sensor_model(*tree, sensor);
  return tree;
}

double map_file_resolution(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw sys_error(Kind::kOpen, "cannot open map", path);
  std::string line;
  for (int i = 0; i < 64 && std::getline(in, line); ++i) {
    if (line == "data") break;
    if (line.rfind("res ", 0) == 0) {
      std::istringstream v(line.substr(4));
      double res = 0;
      if (v >> res && std::isfinite(res) && res > 0) return res;
      break;
    }
  }
  throw MapStoreError(Kind::kCorrupt, "'" + path + "' has no resolution in an OctoMap header");
}

std::string move_map_aside(const std::string& path) {
  const std::string aside = path + ".corrupt-" + utc_stamp();
  if (::rename(path.c_str(), aside.c_str()) != 0) throw sys_error(Kind::kRename, "cannot move aside", path);
  return aside;
}

void check_map_directory_writable(const std::string& map_path) {
  const std::string dir = directory_of(map_path);
  const std::string probe = map_path + ".probe-" + std::to_string(::getpid());
  try {
    write_and_sync(probe, std::string(4096, '\0'), O_EXCL);
    ::unlink(probe.c_str());
    sync_directory(dir);
  } catch (const MapStoreError& e) {
    ::unlink(probe.c_str());
    throw MapStoreError(Kind::kNotWritable, "the map cannot be saved in '" + dir + "' (" + e.what() +
                                                "); fix the directory or choose another --map");
  }
  const std::string stale = map_path + ".tmp";
  std::error_code ec;
  std::filesystem::remove(stale, ec);  // an interrupted save's leftover; the map itself is intact
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  const std::string tmp = path + ".tmp";
  try {
    write_and_sync(tmp, bytes, O_TRUNC);
  } catch (const MapStoreError&) {
    ::unlink(tmp.c_str());
    throw;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const MapStoreError e = sys_error(Kind::kRename, "cannot rename over", path);
    ::unlink(tmp.c_str());
    throw e;
  }
  sync_directory(directory_of(path));
}

}  // namespace ort::daemon
