// Validation of OctoMap tree files before OctoMap's reader sees them: .ot
// (AbstractOcTree::write, log-odds per node) and .bt (OcTree::writeBinary, 2 bits per child).
//
// OctoMap 1.9.7's readers trust the bytes. Truncated data is read as far as it goes without an
// error (a .ot cut in half loads half its nodes and says nothing), the children bits are
// followed with no depth limit (a crafted file recurses until the stack overflows), the .ot
// header's node count is never compared with what was read, and a NaN resolution passes its
// `res <= 0` test. So the check parses the header the way OctoMap does (same stream
// operations), then walks the node stream with its own explicit stack and requires: a known
// first line, tree type OcTree, a finite positive resolution, finite log-odds, no node below
// the 16th level, the data consumed exactly to the end of the file, and as many nodes as
// the header says. Only then may OctoMap read the bytes.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <octomap/OcTree.h>

namespace ort {

enum class OctreeFileFormat { kFull, kBinary };  // .ot, .bt

struct OctreeFileCheck {
  bool ok = false;
  std::string error;  // why not (names the byte offset where it helps)
  OctreeFileFormat format = OctreeFileFormat::kFull;
  std::string tree_type;  // header id ("OcTree")
  double resolution = 0;
  uint64_t header_nodes = 0;  // the header's "size"
  uint64_t nodes = 0;         // nodes the data holds
  size_t data_offset = 0;     // first byte after the header
};

// Checks a whole file held in memory. Never throws on any input. With `inner_is_max` (.ot
// only), every inner node must hold the largest log-odds of its children, as every OctoMap
// tree updated without lazy evaluation does: most overwritten bytes then show even when the
// node structure survives them.
OctreeFileCheck check_octree_file(std::string_view bytes, bool inner_is_max = false);

// Checks `bytes`, then reads them with OctoMap's own reader and checks that it consumed the
// stream to its end and built exactly the checked number of nodes. Throws
// std::runtime_error whose message starts with `name` and says why.
std::unique_ptr<octomap::OcTree> read_octree_file_bytes(std::string_view bytes, const std::string& name,
                                                        bool inner_is_max = false);

}  // namespace ort
