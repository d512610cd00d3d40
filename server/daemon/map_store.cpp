#include "daemon/map_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <octomap/AbstractOcTree.h>

namespace ort::daemon {
namespace {

std::runtime_error sys_error(const std::string& what, const std::string& path) {
  return std::runtime_error(what + " '" + path + "': " + std::strerror(errno));
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string serialize_map(const octomap::OcTree& tree) {
  std::ostringstream out(std::ios::binary);
  if (!tree.write(out)) throw std::runtime_error("could not serialize the map");
  return std::move(out).str();
}

std::unique_ptr<octomap::OcTree> load_map(const std::string& path, double resolution) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open map '" + path + "'");
  std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(in));
  if (!any) throw std::runtime_error("'" + path + "' is not a readable OctoMap .ot file");
  auto* tree = dynamic_cast<octomap::OcTree*>(any.get());
  if (!tree) throw std::runtime_error("'" + path + "' holds a " + any->getTreeType() + ", not an OcTree");
  const double file_res = tree->getResolution();
  // The .ot header prints the resolution as text (6 significant digits), so allow for that
  // rounding, and then use the requested value bit for bit.
  if (std::abs(file_res - resolution) > 1e-6 * resolution) {
    std::ostringstream msg;
    msg << "map '" << path << "' has resolution " << file_res << " m but the server was started with -r "
        << resolution << "; start with -r " << file_res << " or use another --map file";
    throw std::runtime_error(msg.str());
  }
  if (file_res != resolution) tree->setResolution(resolution);
  any.release();
  return std::unique_ptr<octomap::OcTree>(tree);
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  const std::string tmp = path + ".tmp";
  {
    Fd f;
    f.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (f.fd < 0) throw sys_error("cannot create", tmp);
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(f.fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw sys_error("cannot write", tmp);
      done += static_cast<size_t>(n);
    }
    if (::fsync(f.fd) != 0) throw sys_error("cannot fsync", tmp);
    const int fd = f.fd;
    f.fd = -1;
    if (::close(fd) != 0) throw sys_error("cannot close", tmp);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) throw sys_error("cannot rename over", path);
  std::string dir = std::filesystem::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  Fd d;
  d.fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (d.fd < 0 || ::fsync(d.fd) != 0) throw sys_error("cannot fsync directory", dir);
}

}  // namespace ort::daemon
