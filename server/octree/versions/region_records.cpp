#include "octree/versions/region_records.h"

#include <cstring>
#include <limits>

namespace ort {
namespace {

constexpr size_t kRecord = sizeof(float) + 1;

// A node's keys, first and last (inclusive), on one axis.
int64_t first_key(octomap::key_type k, unsigned depth) {
  return depth >= 16 ? int64_t{k} : int64_t{k} - (int64_t{1} << (15 - depth));
}
int64_t last_key(octomap::key_type k, unsigned depth) {
  return depth >= 16 ? int64_t{k} : int64_t{k} + (int64_t{1} << (15 - depth)) - 1;
}

void write_subtree(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                   unsigned depth, RegionBytes& out, LeafExtent& extent) {
  append_record(out.bytes, tree, node);
  ++out.nodes;
  if (!tree.nodeHasChildren(node)) {
    extent.add(tree, key, depth);
    return;
  }
  for_each_child(tree, node, key, depth, [&](const octomap::OcTreeNode* c, const octomap::OcTreeKey& k) {
    write_subtree(tree, c, k, depth + 1, out, extent);
  });
}

// Reading the old records: skip() moves `pos` past one subtree.
struct OldRecords {
  const std::string& bytes;
  size_t pos = 0;

  unsigned child_bits() const { return static_cast<unsigned char>(bytes[pos + sizeof(float)]); }
  void skip() {
    const unsigned bits = child_bits();
    pos += kRecord;
    for (unsigned i = 0; i < 8; ++i)
      if (bits & (1u << i)) skip();
  }
  // The same, its leaves added to `extent`.
  void skip(const octomap::OcTree& tree, const octomap::OcTreeKey& key, unsigned depth, LeafExtent& extent) {
    const unsigned bits = child_bits();
    pos += kRecord;
    if (bits == 0) {
      extent.add(tree, key, depth);
      return;
    }
    const octomap::key_type offset = kRootKey >> (depth + 1);
    for (unsigned i = 0; i < 8; ++i)
      if (bits & (1u << i)) {
        octomap::OcTreeKey child;
        octomap::computeChildKey(i, offset, key, child);
        skip(tree, child, depth + 1, extent);
      }
  }
};

struct Merge {
  const octomap::OcTree& tree;
  OldRecords old;
  const RegionCells& changed;
  unsigned region_depth, levels;
  RegionBytes& out;
  LeafExtent extent;
  uint64_t copied = 0;

  // Whether a cell below the node numbered `prefix` at `rel` levels below the region root changed.
  bool any_changed(unsigned prefix, unsigned rel) const {
    const unsigned span = 1u << (3 * (levels - rel));
    for (unsigned c = prefix * span; c < (prefix + 1) * span; ++c)
      if (changed.test(c)) return true;
    return false;
  }

  // The node (in the tree and, at old.pos, in the old records) whose subtree changed.
  void node(const octomap::OcTreeNode* n, const octomap::OcTreeKey& key, unsigned depth, unsigned prefix) {
    const unsigned rel = depth - region_depth;
    if (rel == levels) {  // a changed cell: written from the tree
      old.skip();
      write_subtree(tree, n, key, depth, out, extent);
      return;
    }
    append_record(out.bytes, tree, n);
    ++out.nodes;
    const unsigned old_bits = old.child_bits();
    old.pos += kRecord;
    const bool leaf = !tree.nodeHasChildren(n);
    if (leaf) extent.add(tree, key, depth);
    const octomap::key_type offset = kRootKey >> (depth + 1);
    for (unsigned i = 0; i < 8; ++i) {
      const bool had = (old_bits & (1u << i)) != 0, has = !leaf && tree.nodeChildExists(n, i);
      if (!had && !has) continue;
      octomap::OcTreeKey child_key;
      octomap::computeChildKey(i, offset, key, child_key);
      if (!has) {  // pruned since
        old.skip();
        continue;
      }
      const octomap::OcTreeNode* child = tree.getNodeChild(n, i);
      if (!had) {  // made since (an expansion, new space)
        write_subtree(tree, child, child_key, depth + 1, out, extent);
        continue;
      }
      const unsigned child_prefix = prefix * 8 + i;
      if (any_changed(child_prefix, rel + 1)) {
        node(child, child_key, depth + 1, child_prefix);
      } else {  // unchanged: its old records as they are
        const size_t from = old.pos;
        old.skip(tree, child_key, depth + 1, extent);
        out.bytes.append(old.bytes, from, old.pos - from);
        out.nodes += (old.pos - from) / kRecord;
        copied += (old.pos - from) / kRecord;
      }
    }
  }
};

void finish(const LeafExtent& e, RegionBytes& out) {
  for (unsigned a = 0; a < 3; ++a) out.min[a] = e.min[a], out.max[a] = e.max[a];
}

}  // namespace

LeafExtent::LeafExtent() {
  for (unsigned a = 0; a < 3; ++a) {
    min[a] = std::numeric_limits<double>::max(), max[a] = -std::numeric_limits<double>::max();
    lo[a] = std::numeric_limits<int64_t>::max(), hi[a] = std::numeric_limits<int64_t>::min();
  }
}

void LeafExtent::add(const octomap::OcTree& tree, const octomap::OcTreeKey& key, unsigned depth) {
  double half = -1;
  for (unsigned a = 0; a < 3; ++a) {
    const int64_t first = first_key(key[a], depth), last = last_key(key[a], depth);
    if (first > lo[a] && last < hi[a]) continue;
    if (half < 0) half = tree.getNodeSize(depth) / 2.0;
    const double c = tree.keyToCoord(key[a], depth);
    if (first <= lo[a]) {
      lo[a] = first;
      if (c - half < min[a]) min[a] = c - half;
    }
    if (last >= hi[a]) {
      hi[a] = last;
      if (c + half > max[a]) max[a] = c + half;
    }
  }
}

void append_record(std::string& out, const octomap::OcTree& tree, const octomap::OcTreeNode* node) {
  const float value = node->getValue();
  char rec[kRecord];
  std::memcpy(rec, &value, sizeof(float));
  unsigned bits = 0;
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) bits |= 1u << i;
  rec[sizeof(float)] = static_cast<char>(bits);
  out.append(rec, sizeof rec);
}

unsigned cell_levels(unsigned region_depth) { return std::min(kCellLevels, 16 - std::min(16u, region_depth)); }

unsigned cell_of(const octomap::OcTreeKey& key, unsigned region_depth) {
  unsigned cell = 0;
  const unsigned levels = cell_levels(region_depth);
  for (unsigned l = region_depth; l < region_depth + levels; ++l) {
    const unsigned bit = 15 - l;
    cell = cell * 8 + (((key[0] >> bit) & 1u) | (((key[1] >> bit) & 1u) << 1) | (((key[2] >> bit) & 1u) << 2));
  }
  return cell;
}

void write_region(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                  unsigned depth, RegionBytes& out) {
  LeafExtent extent;
  write_subtree(tree, node, key, depth, out, extent);
  finish(extent, out);
}

uint64_t merge_region(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                      unsigned depth, const RegionBytes& old, const RegionCells& changed, RegionBytes& out) {
  out.bytes.reserve(old.bytes.size() + old.bytes.size() / 8);
  Merge m{tree, OldRecords{old.bytes}, changed, depth, cell_levels(depth), out, LeafExtent{}};
  m.node(node, key, depth, 0);
  finish(m.extent, out);
  return m.copied;
}

}  // namespace ort
