#include "render/map_file.h"

#include <filesystem>
#include <fstream>

namespace ort::render {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::unique_ptr<octomap::OcTree> read_binary(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MapFileError("cannot open " + path);
  auto tree = std::make_unique<octomap::OcTree>(0.1);  // readBinary takes the file's resolution
  if (!tree->readBinary(in)) throw MapFileError(path + " is not an OctoMap binary (.bt) file");
  return tree;
}

std::unique_ptr<octomap::OcTree> read_full(const std::string& path) {
  std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(path));
  if (!any) throw MapFileError(path + " is not an OctoMap (.ot) file");
  auto* tree = dynamic_cast<octomap::OcTree*>(any.get());
  if (!tree) throw MapFileError(path + " holds a " + any->getTreeType() + ", not an OcTree");
  any.release();
  return std::unique_ptr<octomap::OcTree>(tree);
}

}  // namespace

std::unique_ptr<octomap::OcTree> load_map_file(const std::string& path) {
  if (!std::filesystem::exists(path)) throw MapFileError("no such map file: " + path);
  if (ends_with(path, ".bt")) return read_binary(path);
  if (ends_with(path, ".ot")) return read_full(path);
  throw MapFileError("map file must end in .bt or .ot: " + path);
}

}  // namespace ort::render
