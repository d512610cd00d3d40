#include "core/file_checks/octree_file_check.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <istream>
#include <limits>
#include <stdexcept>
#include <vector>

#include <octomap/AbstractOcTree.h>

#include "core/memory_stream.h"

namespace ort {
namespace {

// OctoMap's first lines (AbstractOcTree::fileHeader, AbstractOccupancyOcTree::binaryFileHeader;
// both protected there).
constexpr std::string_view kFullHeader = "# Octomap OcTree file";
constexpr std::string_view kBinaryHeader = "# Octomap OcTree binary file";
constexpr size_t kTreeDepth = 16;  // OcTree levels below the root

// AbstractOcTree::readHeader, step for step, so that what passes here reads the same there.
bool read_header(std::istream& s, std::string& id, unsigned& size, double& res) {
  auto skip_line = [&s] {
    char c;
    do {
      c = static_cast<char>(s.get());
    } while (s.good() && c != '\n');
  };
  bool header_read = false;
  std::string token;
  while (s.good() && !header_read) {
    s >> token;
    if (token == "data") {
      header_read = true;
      skip_line();
    } else if (token.compare(0, 1, "#") == 0) {
      skip_line();
    } else if (token == "id") {
      s >> id;
    } else if (token == "res") {
      s >> res;
    } else if (token == "size") {
      s >> size;
    } else {
      skip_line();
    }
  }
  return header_read;
}

std::string at(size_t offset) { return " at byte " + std::to_string(offset); }

// One open inner node of the .ot walk.
struct OpenNode {
  unsigned remaining;  // children not yet completed
  float value;
  float max_child;
};

// .ot: per node a float log-odds and one byte of child bits, depth first (readNodesRecurs).
// With `inner_is_max`, every inner node must hold the largest log-odds of its children, as
// OctoMap's updateNode (lazy_eval = false) and updateInnerOccupancy leave it.
std::string walk_full(std::string_view b, size_t& pos, uint64_t& nodes, bool inner_is_max) {
  std::vector<OpenNode> open;
  for (;;) {
    if (b.size() - pos < 5)
      return "the data ends inside node " + std::to_string(nodes) + at(pos) + " (file truncated?)";
    float value;
    std::memcpy(&value, b.data() + pos, sizeof value);
    const unsigned children = std::popcount(static_cast<unsigned char>(b[pos + 4]));
    if (!std::isfinite(value)) return "node " + std::to_string(nodes) + " has a non-finite log-odds" + at(pos);
    if (!open.empty()) open.back().max_child = std::max(open.back().max_child, value);
    pos += 5;
    ++nodes;
    if (children > 0) {
      if (open.size() >= kTreeDepth)
        return "node " + std::to_string(nodes - 1) + " has children below the finest level" + at(pos - 1);
      open.push_back({children, value, -std::numeric_limits<float>::infinity()});
      continue;
    }
    while (!open.empty()) {
      if (--open.back().remaining > 0) break;
      if (inner_is_max && open.back().value != open.back().max_child)
        return "an inner node's log-odds is not the largest of its children's (the data was altered)" + at(pos);
      open.pop_back();
    }
    if (open.empty()) return "";
  }
}

// Pops finished parents after a node completed; true when the root completed.
bool finish_node(std::vector<unsigned>& open_children) {
  while (!open_children.empty()) {
    if (--open_children.back() > 0) return false;
    open_children.pop_back();
  }
  return true;
}

// .bt: per inner node two bytes, 2 bits per child (00 none, 01/10 leaf, 11 inner), the inner
// children's bytes following depth first (readBinaryNode). The root is always read.
std::string walk_binary(std::string_view b, size_t& pos, uint64_t& nodes) {
  std::vector<unsigned> open_children;  // per level: inner children not yet completed
  nodes = 1;
  for (;;) {
    if (b.size() - pos < 2)
      return "the data ends inside an inner node" + at(pos) + " after " + std::to_string(nodes) +
             " nodes (file truncated?)";
    const unsigned bits = static_cast<unsigned char>(b[pos]) | (unsigned(static_cast<unsigned char>(b[pos + 1])) << 8);
    pos += 2;
    unsigned inner = 0;
    for (unsigned i = 0; i < 8; ++i) {
      const unsigned code = (bits >> (2 * i)) & 3u;
      nodes += code != 0;
      inner += code == 3;
    }
    if (inner > 0) {
      if (open_children.size() + 1 >= kTreeDepth) return "an inner node lies below the finest level" + at(pos - 2);
      open_children.push_back(inner);
    } else if (finish_node(open_children)) {
      return "";
    }
  }
}

OctreeFileCheck fail(OctreeFileCheck c, std::string why) {
  c.ok = false;
  c.error = std::move(why);
  return c;
}

}  // namespace

OctreeFileCheck check_octree_file(std::string_view bytes, bool inner_is_max) {
  OctreeFileCheck c;
  MemoryStream s(bytes);
  std::string first;
  std::getline(s, first);
  if (first.compare(0, kBinaryHeader.size(), kBinaryHeader) == 0) {
    c.format = OctreeFileFormat::kBinary;
  } else if (first.compare(0, kFullHeader.size(), kFullHeader) == 0) {
    c.format = OctreeFileFormat::kFull;
  } else {
    return fail(c, "not an OctoMap file (the first line is not '" + std::string(kFullHeader) + "' or '" +
                       std::string(kBinaryHeader) + "')");
  }
  unsigned size = 0;
  if (!read_header(s, c.tree_type, size, c.resolution)) return fail(c, "the header has no 'data' line");
  c.header_nodes = size;
  if (c.tree_type == "1") c.tree_type = "OcTree";  // OctoMap's deprecated id
  if (c.tree_type != "OcTree") return fail(c, "holds a tree of type '" + c.tree_type + "', not an OcTree");
  if (!(std::isfinite(c.resolution) && c.resolution > 0))
    return fail(c, "the header's resolution is not a positive number");
  s.clear();  // tellg() needs a good stream; the header may have ended at the end of the file
  const std::streamoff here = s.tellg();
  if (here < 0) return fail(c, "the header could not be read");
  c.data_offset = static_cast<size_t>(here);
  size_t pos = c.data_offset;
  // OctoMap reads no data for a header size of 0 (.ot and .bt alike).
  if (size > 0) {
    const std::string why = c.format == OctreeFileFormat::kFull ? walk_full(bytes, pos, c.nodes, inner_is_max)
                                                                : walk_binary(bytes, pos, c.nodes);
    if (!why.empty()) return fail(c, why);
  }
  if (pos != bytes.size())
    return fail(c, std::to_string(bytes.size() - pos) + " bytes follow the tree's data" + at(pos));
  if (c.nodes != c.header_nodes)
    return fail(c, "the header says " + std::to_string(c.header_nodes) + " nodes but the data holds " +
                       std::to_string(c.nodes));
  c.ok = true;
  return c;
}

std::unique_ptr<octomap::OcTree> read_octree_file_bytes(std::string_view bytes, const std::string& name,
                                                        bool inner_is_max) {
  const OctreeFileCheck c = check_octree_file(bytes, inner_is_max);
  if (!c.ok) throw std::runtime_error(name + ": " + c.error);
  MemoryStream s(bytes);
  std::unique_ptr<octomap::OcTree> tree;
  if (c.format == OctreeFileFormat::kBinary) {
    tree = std::make_unique<octomap::OcTree>(c.resolution);
    if (!tree->readBinary(s)) throw std::runtime_error(name + ": OctoMap's reader refused the binary tree");
  } else {
    std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(s));
    auto* t = dynamic_cast<octomap::OcTree*>(any.get());
    if (!t) throw std::runtime_error(name + ": OctoMap's reader did not return an OcTree");
    any.release();
    tree.reset(t);
  }
  s.clear();
  if (static_cast<size_t>(s.tellg()) != bytes.size() || tree->size() != c.nodes)
    throw std::runtime_error(name + ": OctoMap's reader stopped at byte " +
                             std::to_string(static_cast<long long>(s.tellg())) + " of " + std::to_string(bytes.size()) +
                             " with " + std::to_string(tree->size()) + " of " + std::to_string(c.nodes) + " nodes");
  return tree;
}

}  // namespace ort
