#include "core/file_checks/octree_binary.h"

#include <array>
#include <cstdint>
#include <sstream>

namespace ort {
namespace {

using Node = octomap::OcTreeNode;
enum Class : int { kFree = 0, kOccupied = 1, kInner = 2 };
constexpr unsigned kDepth = 16;

// Walk 1: how many nodes of each depth prune() would collapse if it did not stop early.
// Returns the node's class once pruning is done below it (a leaf's max-likelihood class, or
// kInner). The root (depth 0) is never collapsed: prune() stops at depth 1.
int count_collapses(const octomap::OcTree& t, const Node* n, unsigned depth, std::array<uint64_t, kDepth + 1>& at,
                    uint64_t& nodes) {
  nodes++;
  if (!t.nodeHasChildren(n)) return t.isNodeOccupied(n) ? kOccupied : kFree;
  bool collapsible = depth >= 1;
  int first = -1;
  for (unsigned i = 0; i < 8; ++i) {
    if (!t.nodeChildExists(n, i)) {
      collapsible = false;
      continue;
    }
    const int c = count_collapses(t, t.getNodeChild(n, i), depth + 1, at, nodes);
    if (c == kInner || (first >= 0 && c != first)) collapsible = false;
    if (first < 0) first = c;
  }
  if (!collapsible) return kInner;
  at[depth]++;
  return first;
}

// Walk 2: OccupancyOcTreeBase::writeBinaryNode on the pruned max-likelihood tree, where a
// node deeper than `stop` that walk 1 found collapsible is a leaf. Appends the node's two
// bytes and its children's data to `out` when it stays inner; returns its class.
int write_node(const octomap::OcTree& t, const Node* n, unsigned depth, unsigned stop, std::string& out) {
  if (!t.nodeHasChildren(n)) return t.isNodeOccupied(n) ? kOccupied : kFree;
  const size_t at = out.size();
  out.append(2, '\0');
  int cls[8];
  bool collapsible = depth > stop;
  int first = -1;
  for (unsigned i = 0; i < 8; ++i) {
    if (!t.nodeChildExists(n, i)) {
      cls[i] = -1;
      collapsible = false;
      continue;
    }
    cls[i] = write_node(t, t.getNodeChild(n, i), depth + 1, stop, out);
    if (cls[i] == kInner || (first >= 0 && cls[i] != first)) collapsible = false;
    if (first < 0) first = cls[i];
  }
  if (collapsible) {  // its children wrote nothing (they are leaves): drop its own two bytes
    out.resize(at);
    return first;
  }
  // Two bits per child, child i at bits 2i, 2i+1 of byte i / 4: free 01, occupied 10,
  // children 11, none 00 (std::bitset's bit k is value bit k, as OctoMap writes them).
  unsigned char bytes[2] = {0, 0};
  for (unsigned i = 0; i < 8; ++i) {
    const unsigned shift = 2 * (i % 4);
    const unsigned bits = cls[i] == kFree ? 1u : cls[i] == kOccupied ? 2u : cls[i] == kInner ? 3u : 0u;
    bytes[i / 4] = static_cast<unsigned char>(bytes[i / 4] | (bits << shift));
  }
  out[at] = static_cast<char>(bytes[0]);
  out[at + 1] = static_cast<char>(bytes[1]);
  return kInner;
}

}  // namespace

std::string octomap_binary_bytes(const octomap::OcTree& tree) {
  std::string data;
  uint64_t nodes = 0;
  if (const Node* root = tree.getRoot()) {
    std::array<uint64_t, kDepth + 1> at{};
    count_collapses(tree, root, 0, at, nodes);
    // prune() goes from depth 15 up and stops after the first depth where it collapsed nothing.
    unsigned stop = 0;
    for (unsigned d = kDepth - 1; d >= 1; --d)
      if (at[d] == 0) {
        stop = d;
        break;
      }
    uint64_t collapsed = 0;
    for (unsigned d = stop + 1; d < kDepth; ++d) collapsed += at[d];
    nodes -= 8 * collapsed;
    write_node(tree, root, 0, stop, data);
  }
  // OctoMap's header, written as writeBinaryConst writes it (same stream, same precision).
  std::ostringstream out;
  out << "# Octomap OcTree binary file\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n";
  out << "id " << tree.getTreeType() << std::endl;
  out << "size " << nodes << std::endl;
  out << "res " << tree.getResolution() << std::endl;
  out << "data" << std::endl;
  out << data;
  return std::move(out).str();
}

bool write_octomap_binary(const octomap::OcTree& tree, std::ostream& out) {
  const std::string bytes = octomap_binary_bytes(tree);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out);
}

}  // namespace ort
