// `octomap-rt map diff A B`: do two maps (.ot or .bt) classify every finest voxel alike?
// Prints the voxels known in one map only, of other class, and (both .ot) of other log-odds.
#include <cstdio>
#include <memory>
#include <stdexcept>

#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>

#include "cli/map_commands.h"

namespace ort::cli {
namespace {

std::unique_ptr<octomap::OcTree> load_any(const std::string& path) {
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".bt") == 0) {
    auto t = std::make_unique<octomap::OcTree>(0.1);
    if (!t->readBinary(path)) throw std::runtime_error("cannot read '" + path + "' as .bt");
    return t;
  }
  std::unique_ptr<octomap::AbstractOcTree> a(octomap::AbstractOcTree::read(path));
  auto* t = dynamic_cast<octomap::OcTree*>(a.get());
  if (!t) throw std::runtime_error("cannot read '" + path + "' as an .ot OcTree");
  a.release();
  return std::unique_ptr<octomap::OcTree>(t);
}

}  // namespace

int run_map_diff(const std::string& a_path, const std::string& b_path) {
  auto a = load_any(a_path), b = load_any(b_path);
  if (a->getResolution() != b->getResolution()) throw std::runtime_error("the maps have different resolutions");
  a->expand();
  b->expand();
  size_t voxels = 0, known_in_one = 0, other_class = 0, other_logodds = 0;
  for (auto it = a->begin_leafs(), end = a->end_leafs(); it != end; ++it) {
    ++voxels;
    const octomap::OcTreeNode* n = b->search(it.getKey());
    if (!n) {
      ++known_in_one;
    } else {
      if (a->isNodeOccupied(*it) != b->isNodeOccupied(n)) ++other_class;
      if (it->getLogOdds() != n->getLogOdds()) ++other_logodds;
    }
  }
  for (auto it = b->begin_leafs(), end = b->end_leafs(); it != end; ++it)
    if (!a->search(it.getKey())) ++known_in_one;
  std::printf("%zu voxels: %zu known in one map only, %zu of another class, %zu of other log-odds -> %s\n", voxels,
              known_in_one, other_class, other_logodds, known_in_one + other_class == 0 ? "same classes" : "DIFFERENT");
  return known_in_one + other_class == 0 ? 0 : 1;
}

}  // namespace ort::cli
